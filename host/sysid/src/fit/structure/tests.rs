//! Tests of structure files: parsing, constants, and the line every error names.

use std::collections::BTreeMap;

use super::*;
use crate::fit::error::{StructureError, StructureProblem};
use crate::fit::model::Actuator;

const SMALL: &str = r#"
name = "first-order"
states = ["x"]
controls = ["u"]
outputs = ["x", "y"]

[parameters]
a = { start = -2.0, max = 0.0 }
b = 3.0
c = { fixed = 0.5 }
d = { expr = "-2*b + 1" }
tau = { start = 0.01, min = 0.0 }

[F.x]
x = "a"

[G.x]
u = "b"

[H0.y]
x = "c"

[H1.y]
x = "d"

[delays]
u = "tau"

[[pairs]]
output = "x"
input = "u"
range = [0.1, 10.0]

[[pairs]]
output = "y"
input = "u"
"#;

fn error_of(text: &str) -> StructureError {
    ModelStructure::parse(text, "test.toml").unwrap_err()
}

#[test]
fn parses_a_small_structure() {
    let structure = ModelStructure::parse(SMALL, "small.toml").unwrap();
    assert_eq!(structure.parameters.len(), 4);
    assert_eq!(structure.free_indices().len(), 3);
    assert_eq!(structure.derived.len(), 1);
    assert_eq!(structure.pairs.len(), 2);
    assert_eq!(structure.pairs[0].range, PairRange::Explicit([0.1, 10.0]));
    assert_eq!(structure.pairs[1].range, PairRange::Auto);
    assert_eq!(structure.pairs[1].line, 34);
    let model = structure.model(&structure.values()).unwrap();
    assert_eq!(model.f[(0, 0)], -2.0);
    assert_eq!(model.g[(0, 0)], 3.0);
    // Output x measures the state by default, output y through H0/H1.
    assert_eq!(model.h0[(0, 0)], 1.0);
    assert_eq!(model.h0[(1, 0)], 0.5);
    assert_eq!(model.h1[(1, 0)], -5.0);
    assert_eq!(model.delays[0], 0.01);
    assert_eq!(
        structure.parameter_value("d", &structure.values()),
        Some(-5.0)
    );
}

#[test]
fn constants_enter_expressions_and_can_be_overridden() {
    let text = SMALL
        .replace("[parameters]", "[constants]\narm = 2.0\n\n[parameters]")
        .replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a - arm*b\"");
    let structure = ModelStructure::parse(&text, "arm.toml").unwrap();
    assert_eq!(structure.constants["arm"], 2.0);
    // F = a − arm·b = −2 − 2·3.
    let model = structure.model(&structure.values()).unwrap();
    assert_eq!(model.f[(0, 0)], -8.0);
    // A constant is no parameter: nothing to fit.
    assert!(structure.parameter_index("arm").is_none());

    let overrides = BTreeMap::from([("arm".to_string(), 0.5)]);
    let other = ModelStructure::parse_with_constants(&text, "arm.toml", &overrides).unwrap();
    assert_eq!(other.constants["arm"], 0.5);
    assert_eq!(other.model(&other.values()).unwrap().f[(0, 0)], -3.5);

    let misspelt = BTreeMap::from([("amr".to_string(), 0.5)]);
    let error = ModelStructure::parse_with_constants(&text, "arm.toml", &misspelt).unwrap_err();
    assert!(
        error.to_string().contains("unknown constant `amr`"),
        "{error}"
    );

    let clash = text.replace("arm = 2.0", "arm = 2.0\nb = 1.0");
    let error = ModelStructure::parse(&clash, "clash.toml").unwrap_err();
    assert!(
        error.to_string().contains("`b` is declared twice"),
        "{error}"
    );
}

#[test]
fn from_str_parses_and_names_the_source() {
    let structure: ModelStructure = SMALL.parse().unwrap();
    assert_eq!(structure.source_name, "<string>");
    let error = "name = ".parse::<ModelStructure>().unwrap_err();
    assert!(error.to_string().starts_with("<string>, line 1"), "{error}");
}

#[test]
fn syntax_error_names_the_line() {
    let text = SMALL.replace("b = 3.0", "b = = 3.0");
    let error = error_of(&text);
    assert_eq!(error.line, Some(9), "{error}");
    assert!(matches!(error.problem, StructureProblem::Syntax(_)));
    assert!(error.to_string().contains("test.toml, line 9"), "{error}");
}

#[test]
fn wrong_value_types_are_explained() {
    let error = error_of(&SMALL.replace("b = 3.0", "b = \"Zq\""));
    assert_eq!(error.line, Some(9));
    assert!(
        error.to_string().contains("a parameter is a number"),
        "{error}"
    );
    let error = error_of(&SMALL.replace("x = \"a\"", "x = [1]"));
    assert_eq!(error.line, Some(15));
    assert!(error.to_string().contains("string expression"), "{error}");
}

#[test]
fn unknown_state_names_the_line() {
    let text = SMALL.replace("[G.x]\nu = \"b\"", "[G.x]\nu = \"b\"\n[G.z]\nu = 1.0");
    let error = error_of(&text);
    assert_eq!(error.line, Some(19), "{error}");
    assert_eq!(
        error.problem,
        StructureProblem::UnknownName {
            kind: "state",
            name: "z".into()
        }
    );
    let text = SMALL.replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a\"\nqq = 2.0");
    let error = error_of(&text);
    assert_eq!(error.line, Some(16), "{error}");
}

#[test]
fn undefined_parameter_names_the_line() {
    let text = SMALL.replace("x = \"c\"", "x = \"c + Zq\"");
    let error = error_of(&text);
    assert_eq!(error.line, Some(21), "{error}");
    assert_eq!(
        error.problem,
        StructureProblem::UndefinedParameter("Zq".into())
    );
    assert!(error.to_string().contains("undefined parameter `Zq`"));
}

#[test]
fn non_finite_numbers_are_refused_naming_the_parameter_and_line() {
    for (from, to, line, message) in [
        (
            "b = 3.0",
            "b = nan",
            9,
            "parameter `b` = NaN is not a finite number",
        ),
        (
            "b = 3.0",
            "b = -inf",
            9,
            "parameter `b` = -inf is not a finite number",
        ),
        (
            "a = { start = -2.0, max = 0.0 }",
            "a = { start = inf, max = 0.0 }",
            8,
            "parameter `a` = inf is not a finite number",
        ),
        (
            "c = { fixed = 0.5 }",
            "c = { fixed = nan }",
            10,
            "parameter `c` = NaN is not a finite number",
        ),
        (
            "tau = { start = 0.01, min = 0.0 }",
            "tau = { start = 0.01, min = nan }",
            12,
            "parameter `tau`: min = NaN is not a finite number",
        ),
        (
            "a = { start = -2.0, max = 0.0 }",
            "a = { start = -2.0, max = inf }",
            8,
            "parameter `a`: max = inf is not a finite number",
        ),
        (
            "[F.x]\nx = \"a\"",
            "[F.x]\nx = nan",
            15,
            "entry F[x, x] = NaN is not a finite number",
        ),
        (
            "u = \"tau\"",
            "u = inf",
            27,
            "delay of `u` = inf is not a finite number",
        ),
    ] {
        let text = SMALL.replace(from, to);
        assert_ne!(text, SMALL, "{from}");
        let error = error_of(&text);
        assert_eq!(error.line, Some(line), "{error}");
        assert_eq!(
            error.to_string(),
            format!("test.toml, line {line}: {message}")
        );
    }
}

#[test]
fn bounds_must_be_ordered_and_hold_the_start() {
    for (from, to, reason) in [
        (
            "a = { start = -2.0, max = 0.0 }",
            "a = { start = -2.0, min = 0.0, max = -3.0 }",
            "`min` must be below `max`",
        ),
        (
            "a = { start = -2.0, max = 0.0 }",
            "a = { start = -2.0, min = 1.0, max = 1.0 }",
            "`min` must be below `max`",
        ),
        (
            "a = { start = -2.0, max = 0.0 }",
            "a = { start = 1.0, max = 0.0 }",
            "outside [min, max]",
        ),
        (
            "c = { fixed = 0.5 }",
            "c = { fixed = 0.5, min = 1.0 }",
            "outside [min, max]",
        ),
        (
            "d = { expr = \"-2*b + 1\" }",
            "d = { expr = \"-2*b + 1\", max = 1.0 }",
            "cannot have bounds",
        ),
    ] {
        let error = error_of(&SMALL.replace(from, to));
        assert!(
            matches!(error.problem, StructureProblem::BadParameter { .. }),
            "{error}"
        );
        assert!(error.to_string().contains(reason), "{error}");
    }
}

#[test]
fn a_parameter_no_entry_uses_is_refused_naming_it() {
    let tau = "tau = { start = 0.01, min = 0.0 }";
    let error = error_of(&SMALL.replace(tau, &format!("{tau}\nFoo = 1.0")));
    assert_eq!(error.line, Some(13), "{error}");
    assert_eq!(
        error.to_string(),
        "test.toml, line 13: parameter `Foo` is declared but used in no matrix entry or delay"
    );
    // Fixed and constrained ones too, all named at once; a base parameter that only an
    // unused constrained one names is unused.
    let text = SMALL.replace(
        tau,
        &format!("{tau}\ne = {{ fixed = 1.0 }}\nf = {{ expr = \"2*e\" }}"),
    );
    let error = error_of(&text);
    assert_eq!(error.line, Some(13), "{error}");
    assert_eq!(
        error.problem,
        StructureProblem::UnusedParameters(vec!["e".into(), "f".into()])
    );
    assert!(
        error
            .to_string()
            .contains("parameters `e`, `f` are declared"),
        "{error}"
    );
    // A parameter whose coefficients cancel has no effect: unused.
    let text = SMALL
        .replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a + c - c\"")
        .replace("[H0.y]\nx = \"c\"", "[H0.y]\nx = 0.5");
    let error = error_of(&text);
    assert_eq!(
        error.problem,
        StructureProblem::UnusedParameters(vec!["c".into()])
    );
    assert_eq!(error.line, Some(10));
    // Used through a constrained parameter (and a delay) is used.
    let text = SMALL
        .replace(tau, &format!("{tau}\ng = {{ expr = \"a\" }}"))
        .replace("\"-2*b + 1\"", "\"g - 2*b + 1\"");
    ModelStructure::parse(&text, "chain.toml").unwrap();
}

#[test]
fn other_semantic_errors_name_the_line() {
    let error = error_of(&SMALL.replace("\"-2*b + 1\"", "\"b * a\""));
    assert_eq!(error.line, Some(11));
    assert!(matches!(
        error.problem,
        StructureProblem::BadExpression { .. }
    ));

    let cyclic = SMALL
        .replace("c = { fixed = 0.5 }", "c = { expr = \"d\" }")
        .replace("\"-2*b + 1\"", "\"2*c\"");
    let error = error_of(&cyclic);
    assert!(
        matches!(error.problem, StructureProblem::CyclicConstraint(_)),
        "{error}"
    );
    assert_eq!(error.line, Some(10));

    let error = error_of(&SMALL.replace("range = [0.1, 10.0]", "range = [10.0, 0.1]"));
    assert_eq!(error.line, Some(32));
    assert!(matches!(error.problem, StructureProblem::BadRange(_)));

    let error = error_of(&SMALL.replace(
        "output = \"y\"\ninput = \"u\"",
        "output = \"y\"\ninput = \"v\"",
    ));
    assert_eq!(error.line, Some(36), "{error}");
    assert!(matches!(
        error.problem,
        StructureProblem::UnknownName {
            kind: "control",
            ..
        }
    ));

    let error = error_of(&SMALL.replace("b = 3.0", "b = { start = 3.0, fixed = 1.0 }"));
    assert_eq!(error.line, Some(9));
    assert!(matches!(
        error.problem,
        StructureProblem::BadParameter { .. }
    ));

    let error = error_of(&SMALL.replace("outputs = [\"x\", \"y\"]", "outputs = [\"x\", \"x\"]"));
    assert_eq!(error.line, Some(5));
    assert_eq!(error.problem, StructureProblem::DuplicateName("x".into()));

    let error = error_of(&SMALL.replace("[[pairs]]\noutput = \"y\"", "[[pairs]]\noutput = \"x\""));
    assert!(matches!(error.problem, StructureProblem::DuplicateName(_)));
    assert_eq!(error.line, Some(34));
}

#[test]
fn actuators_take_numbers_or_constants_and_refuse_anything_else() {
    let with = |table: &str| {
        SMALL.replace(
            "[delays]",
            &format!("[constants]\nservo_w = 60.0\n\n[actuators]\n{table}\n\n[delays]"),
        )
    };
    let structure = ModelStructure::parse(
        &with(r#"u = { natural_frequency = "servo_w", damping = 0.7 }"#),
        "a.toml",
    )
    .unwrap();
    let expected = Actuator {
        natural_frequency_rad_s: 60.0,
        damping: 0.7,
    };
    assert_eq!(structure.actuators, vec![Some(expected)]);
    let model = structure.model(&structure.values()).unwrap();
    assert_eq!(model.actuators, vec![Some(expected)]);
    // Without the table there is none.
    assert_eq!(
        ModelStructure::parse(SMALL, "s.toml").unwrap().actuators,
        vec![None]
    );

    let problem = |table: &str| error_of(&with(table));
    let unknown = problem(r#"u = { natural_frequency = "b", damping = 0.7 }"#);
    assert!(
        matches!(&unknown.problem, StructureProblem::BadActuator { control, reason }
            if control == "u" && reason.contains("`b`")),
        "{unknown}"
    );
    assert_eq!(unknown.line, Some(30));
    let negative = problem("u = { natural_frequency = 60.0, damping = -0.7 }");
    assert!(
        matches!(negative.problem, StructureProblem::BadActuator { .. }),
        "{negative}"
    );
    let not_a_control = problem("v = { natural_frequency = 60.0, damping = 0.7 }");
    assert!(
        matches!(
            not_a_control.problem,
            StructureProblem::UnknownName {
                kind: "control",
                ..
            }
        ),
        "{not_a_control}"
    );
    let missing = problem("u = { natural_frequency = 60.0 }");
    assert!(
        matches!(missing.problem, StructureProblem::Syntax(_)),
        "{missing}"
    );
}

/// SMALL with the entry F[x, x] written as `expression`.
fn small_with_dynamics(expression: &str) -> String {
    SMALL.replace("[F.x]\nx = \"a\"", &format!("[F.x]\nx = \"{expression}\""))
}

#[test]
fn deeply_nested_expressions_are_refused_at_their_line_not_overflowed() {
    // 20 000 levels of parentheses: refused by the depth limit, in one short line.
    let nested = format!("{}a{}", "(".repeat(20_000), ")".repeat(20_000));
    let error = error_of(&small_with_dynamics(&nested));
    assert_eq!(error.line, Some(15));
    let message = error.to_string();
    assert!(
        message.contains("parentheses nested deeper than 64 levels"),
        "{message}"
    );
    assert!(!message.contains('\n') && message.len() < 200, "{message}");
    // At the limit it parses.
    let at_limit = format!("{}a{}", "(".repeat(64), ")".repeat(64));
    ModelStructure::parse(&small_with_dynamics(&at_limit), "test.toml").unwrap();
    // A chain of 20 000 signs is read in a loop: no limit needed, the sign is right.
    let signs = format!("{}a", "- ".repeat(20_001));
    let structure = ModelStructure::parse(&small_with_dynamics(&signs), "test.toml").unwrap();
    let model = structure.model(&structure.values()).unwrap();
    assert_eq!(model.f[(0, 0)], 2.0, "-(−2): an odd number of signs");
}

#[test]
fn a_long_chain_of_constrained_parameters_is_refused() {
    let mut text = SMALL.replace("x = \"a\"", "x = \"a + k200\"");
    let mut chain = String::from("k0 = { expr = \"a\" }\n");
    for k in 1..=200 {
        chain.push_str(&format!("k{k} = {{ expr = \"k{}\" }}\n", k - 1));
    }
    text = text.replace("[parameters]\n", &format!("[parameters]\n{chain}"));
    let error = error_of(&text);
    assert!(
        matches!(error.problem, StructureProblem::ConstraintChainTooLong(_)),
        "{error}"
    );
}

#[test]
fn an_undeclared_constant_in_a_product_is_named() {
    let error = error_of(&small_with_dynamics("rotor_k*a"));
    assert_eq!(error.line, Some(15));
    assert!(
        error
            .to_string()
            .contains("`rotor_k` is not a declared constant or parameter"),
        "{error}"
    );
    let error = error_of(&small_with_dynamics("a / rotor_k"));
    assert!(
        error.to_string().contains("`rotor_k` is not a declared"),
        "{error}"
    );
    // Two declared parameters multiplied are still called what they are.
    let error = error_of(&small_with_dynamics("a*b"));
    assert!(
        error
            .to_string()
            .contains("a product of two parameters is not linear"),
        "{error}"
    );
}

#[test]
fn an_output_nothing_defines_is_refused_naming_it() {
    // `z` is no state and has no H0/H1 row: its response would be 0.
    let text = SMALL.replace(
        "outputs = [\"x\", \"y\"]",
        "outputs = [\"x\", \"y\",\n  \"z\"]",
    );
    let error = error_of(&text);
    assert_eq!(
        error.problem,
        StructureProblem::UndefinedOutput("z".to_string())
    );
    assert_eq!(error.line, Some(6));
}

/// A structure with `states` states, each fitted on its own pair: F[i, i] = a_i,
/// G[i, u] = b_i.
fn diagonal_structure(states: usize) -> String {
    let names: Vec<String> = (0..states).map(|i| format!("\"x{i}\"")).collect();
    let mut text = format!(
        "name = \"big\"\nstates = [{list}]\ncontrols = [\"u\"]\noutputs = [{list}]\n\n[parameters]\n",
        list = names.join(", ")
    );
    for i in 0..states {
        text.push_str(&format!("a{i} = -1.0\nb{i} = 1.0\n"));
    }
    for i in 0..states {
        text.push_str(&format!(
            "[F.x{i}]\nx{i} = \"a{i}\"\n[G.x{i}]\nu = \"b{i}\"\n"
        ));
    }
    for i in 0..states {
        text.push_str(&format!("[[pairs]]\noutput = \"x{i}\"\ninput = \"u\"\n"));
    }
    text
}

#[test]
fn structures_beyond_the_size_limits_are_refused_before_any_work() {
    let started = std::time::Instant::now();
    let error = error_of(&diagonal_structure(1_000));
    assert_eq!(
        error.problem,
        StructureProblem::TooLarge {
            what: "states",
            count: 1_000,
            limit: MAX_STATES
        }
    );
    assert_eq!(error.line, Some(2));
    assert!(started.elapsed().as_secs_f64() < 5.0);
    // At the limit: accepted.
    ModelStructure::parse(&diagonal_structure(MAX_STATES), "test.toml").unwrap();

    // Parameters: 257 declared, with the states within their limit.
    let mut text = diagonal_structure(1);
    let extra: String = (0..MAX_PARAMETERS)
        .map(|k| format!("p{k} = 0.0\n"))
        .collect();
    text = text.replace("[parameters]\n", &format!("[parameters]\n{extra}"));
    let error = error_of(&text);
    assert!(
        matches!(
            error.problem,
            StructureProblem::TooLarge { what: "parameters", count, limit: MAX_PARAMETERS }
                if count == MAX_PARAMETERS + 2
        ),
        "{error}"
    );
    // The first parameter beyond the limit: p0..p255 on lines 7.., then a0 b0.
    assert_eq!(error.line, Some(7 + MAX_PARAMETERS));

    // Pairs: 129 of them (duplicates would be refused later; the size comes first).
    let mut text = diagonal_structure(1);
    text.push_str(&"[[pairs]]\noutput = \"x0\"\ninput = \"u\"\n".repeat(MAX_PAIRS));
    let error = error_of(&text);
    assert!(
        matches!(
            error.problem,
            StructureProblem::TooLarge {
                what: "pairs",
                limit: MAX_PAIRS,
                ..
            }
        ),
        "{error}"
    );
}
