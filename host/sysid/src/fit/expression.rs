//! Linear expressions of parameters, as written in structure files: `Xu`, `-tau_f`,
//! `2.5 * Lp`, `Lp / 0.064`, `-(Xb1c)`, `0.5*Lr - 0.1*Nr + 3`.
//!
//! Grammar (recursive descent; products and quotients need a constant on one side, so
//! every expression is `c0 + Σ c_k·θ_k`):
//!
//! ```text
//! expr   := term (('+' | '-') term)*
//! term   := factor (('*' | '/') factor)*
//! factor := ('-' | '+')* (number | name | '(' expr ')')
//! ```
//!
//! Signs before a factor are read in a loop, and parentheses may nest at most
//! [`MAX_NESTING`] deep, so no expression — however long — can exhaust the stack.

use std::collections::{BTreeMap, BTreeSet};

/// Deepest nesting of parentheses an expression may have. The parser recurses once per
/// level; a structure file needs two or three, and 64 keeps the recursion far below any
/// thread's stack.
pub const MAX_NESTING: usize = 64;

/// `constant + Σ coefficient·name`, with names not yet resolved to parameters.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct LinearForm {
    /// The constant part c0.
    pub constant: f64,
    /// Coefficient per parameter name (zero coefficients removed).
    pub terms: BTreeMap<String, f64>,
}

impl LinearForm {
    fn constant(value: f64) -> Self {
        Self {
            constant: value,
            terms: BTreeMap::new(),
        }
    }

    fn name(name: &str) -> Self {
        let mut terms = BTreeMap::new();
        terms.insert(name.to_string(), 1.0);
        Self {
            constant: 0.0,
            terms,
        }
    }

    fn is_constant(&self) -> bool {
        self.terms.is_empty()
    }

    fn scaled(mut self, factor: f64) -> Self {
        self.constant *= factor;
        for coefficient in self.terms.values_mut() {
            *coefficient *= factor;
        }
        self
    }

    fn plus(mut self, other: Self, sign: f64) -> Self {
        self.constant += sign * other.constant;
        for (name, coefficient) in other.terms {
            *self.terms.entry(name).or_insert(0.0) += sign * coefficient;
        }
        self.terms.retain(|_, coefficient| *coefficient != 0.0);
        self
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    Plus,
    Minus,
    Star,
    Slash,
    Open,
    Close,
}

fn tokenize(text: &str) -> Result<Vec<Token>, String> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    let mut index = 0;
    while index < bytes.len() {
        let c = bytes[index] as char;
        match c {
            ' ' | '\t' => index += 1,
            '+' => {
                tokens.push(Token::Plus);
                index += 1;
            }
            '-' => {
                tokens.push(Token::Minus);
                index += 1;
            }
            '*' => {
                tokens.push(Token::Star);
                index += 1;
            }
            '/' => {
                tokens.push(Token::Slash);
                index += 1;
            }
            '(' => {
                tokens.push(Token::Open);
                index += 1;
            }
            ')' => {
                tokens.push(Token::Close);
                index += 1;
            }
            '0'..='9' | '.' => {
                let start = index;
                while index < bytes.len() {
                    let d = bytes[index] as char;
                    let exponent_sign = (d == '+' || d == '-')
                        && index > start
                        && matches!(bytes[index - 1] as char, 'e' | 'E');
                    if d.is_ascii_digit() || d == '.' || d == 'e' || d == 'E' || exponent_sign {
                        index += 1;
                    } else {
                        break;
                    }
                }
                let literal = &text[start..index];
                let value: f64 = literal
                    .parse()
                    .map_err(|_| format!("`{literal}` is not a number"))?;
                tokens.push(Token::Number(value));
            }
            c if c.is_ascii_alphabetic() || c == '_' => {
                let start = index;
                while index < bytes.len()
                    && ((bytes[index] as char).is_ascii_alphanumeric() || bytes[index] == b'_')
                {
                    index += 1;
                }
                tokens.push(Token::Name(text[start..index].to_string()));
            }
            other => return Err(format!("unexpected character `{other}`")),
        }
    }
    Ok(tokens)
}

struct Parser<'a> {
    tokens: Vec<Token>,
    position: usize,
    /// Open parentheses around the current position.
    depth: usize,
    /// The structure's parameter names, when known: a product of two names then says
    /// which of them is declared nowhere (a constant left out of `[constants]`).
    parameters: Option<&'a BTreeSet<String>>,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.position)
    }

    fn next(&mut self) -> Option<Token> {
        let token = self.tokens.get(self.position).cloned();
        self.position += 1;
        token
    }

    fn expression(&mut self) -> Result<LinearForm, String> {
        let mut value = self.term()?;
        while let Some(token) = self.peek() {
            let sign = match token {
                Token::Plus => 1.0,
                Token::Minus => -1.0,
                _ => break,
            };
            self.position += 1;
            let rhs = self.term()?;
            value = value.plus(rhs, sign);
        }
        Ok(value)
    }

    fn term(&mut self) -> Result<LinearForm, String> {
        let mut value = self.factor()?;
        while let Some(token) = self.peek() {
            let divide = match token {
                Token::Star => false,
                Token::Slash => true,
                _ => break,
            };
            self.position += 1;
            let rhs = self.factor()?;
            value = if divide {
                if !rhs.is_constant() {
                    return Err(self
                        .undeclared(&rhs)
                        .unwrap_or_else(|| "division by a parameter is not linear".into()));
                }
                if rhs.constant == 0.0 {
                    return Err("division by zero".into());
                }
                value.scaled(1.0 / rhs.constant)
            } else if rhs.is_constant() {
                value.scaled(rhs.constant)
            } else if value.is_constant() {
                rhs.scaled(value.constant)
            } else {
                return Err(self.product_of_names(&value, &rhs));
            };
        }
        Ok(value)
    }

    fn factor(&mut self) -> Result<LinearForm, String> {
        let mut sign = 1.0;
        loop {
            match self.next() {
                Some(Token::Minus) => sign = -sign,
                Some(Token::Plus) => {}
                Some(Token::Number(value)) => return Ok(LinearForm::constant(sign * value)),
                Some(Token::Name(name)) => return Ok(LinearForm::name(&name).scaled(sign)),
                Some(Token::Open) => {
                    if self.depth == MAX_NESTING {
                        return Err(format!(
                            "parentheses nested deeper than {MAX_NESTING} levels"
                        ));
                    }
                    self.depth += 1;
                    let inner = self.expression()?;
                    self.depth -= 1;
                    return match self.next() {
                        Some(Token::Close) => Ok(inner.scaled(sign)),
                        _ => Err("missing `)`".into()),
                    };
                }
                Some(other) => return Err(format!("unexpected `{}`", token_text(&other))),
                None => return Err("unexpected end of expression".into()),
            }
        }
    }

    /// The first name of `form` that is neither a constant (those were replaced by their
    /// numbers before parsing) nor a declared parameter, as an error; None when every
    /// name is declared or the parameters are not known.
    fn undeclared(&self, form: &LinearForm) -> Option<String> {
        let parameters = self.parameters?;
        form.terms
            .keys()
            .find(|name| !parameters.contains(*name))
            .map(|name| {
                format!(
                    "`{name}` is not a declared constant or parameter (declare it under \
                     [constants] or [parameters])"
                )
            })
    }

    /// Why `left * right`, both with names, is refused: an undeclared name (most often a
    /// constant missing from `[constants]`), else a true product of two parameters.
    fn product_of_names(&self, left: &LinearForm, right: &LinearForm) -> String {
        self.undeclared(left)
            .or_else(|| self.undeclared(right))
            .unwrap_or_else(|| "a product of two parameters is not linear".into())
    }
}

fn token_text(token: &Token) -> String {
    match token {
        Token::Number(value) => value.to_string(),
        Token::Name(name) => name.clone(),
        Token::Plus => "+".into(),
        Token::Minus => "-".into(),
        Token::Star => "*".into(),
        Token::Slash => "/".into(),
        Token::Open => "(".into(),
        Token::Close => ")".into(),
    }
}

/// Parse a linear expression; the error says why it is not one.
pub fn parse_linear(text: &str) -> Result<LinearForm, String> {
    parse_linear_with_constants(text, &BTreeMap::new())
}

/// Parse a linear expression in which the names in `constants` stand for their numbers
/// (a structure file's `[constants]`, e.g. a hub height): `hub_height*Mfu` is then the
/// linear `1.48·Mfu`, where two parameters multiplied would not be.
pub fn parse_linear_with_constants(
    text: &str,
    constants: &BTreeMap<String, f64>,
) -> Result<LinearForm, String> {
    parse(text, constants, None)
}

/// [`parse_linear_with_constants`] for an expression of a structure whose parameter
/// names are `parameters`: a product or quotient with a name declared neither there nor
/// among the constants says so, naming it, instead of calling it a product of two
/// parameters.
pub fn parse_linear_declared(
    text: &str,
    constants: &BTreeMap<String, f64>,
    parameters: &BTreeSet<String>,
) -> Result<LinearForm, String> {
    parse(text, constants, Some(parameters))
}

fn parse(
    text: &str,
    constants: &BTreeMap<String, f64>,
    parameters: Option<&BTreeSet<String>>,
) -> Result<LinearForm, String> {
    let tokens: Vec<Token> = tokenize(text)?
        .into_iter()
        .map(|token| match token {
            Token::Name(name) => match constants.get(&name) {
                Some(&value) => Token::Number(value),
                None => Token::Name(name),
            },
            other => other,
        })
        .collect();
    if tokens.is_empty() {
        return Err("empty expression".into());
    }
    let mut parser = Parser {
        tokens,
        position: 0,
        depth: 0,
        parameters,
    };
    let value = parser.expression()?;
    if let Some(token) = parser.peek() {
        return Err(format!("unexpected `{}`", token_text(token)));
    }
    if !value.constant.is_finite() || value.terms.values().any(|c| !c.is_finite()) {
        return Err("coefficient is not finite".into());
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_stand_for_their_numbers() {
        let constants = BTreeMap::from([("hub_height".to_string(), 1.5)]);
        let form = parse_linear_with_constants("-tau_f - hub_height*Mfu", &constants).unwrap();
        assert_eq!(coefficient(&form, "tau_f"), -1.0);
        assert_eq!(coefficient(&form, "Mfu"), -1.5);
        assert!(!form.terms.contains_key("hub_height"));
        // Without the constant it is a product of two names, which is not linear.
        assert!(parse_linear("-tau_f - hub_height*Mfu").is_err());
    }

    fn coefficient(form: &LinearForm, name: &str) -> f64 {
        form.terms.get(name).copied().unwrap_or(0.0)
    }

    #[test]
    fn parses_linear_combinations() {
        let form = parse_linear("-tau_f").unwrap();
        assert_eq!(coefficient(&form, "tau_f"), -1.0);
        assert_eq!(form.constant, 0.0);

        let form = parse_linear("0.5*Lr - Nr/4 + 3 - 2e-1").unwrap();
        assert_eq!(coefficient(&form, "Lr"), 0.5);
        assert_eq!(coefficient(&form, "Nr"), -0.25);
        assert!((form.constant - 2.8).abs() < 1e-15);

        let form = parse_linear("-(Xb1c - 2*Yv) * 3").unwrap();
        assert_eq!(coefficient(&form, "Xb1c"), -3.0);
        assert_eq!(coefficient(&form, "Yv"), 6.0);

        let form = parse_linear("Xu - Xu").unwrap();
        assert!(form.terms.is_empty());
    }

    #[test]
    fn rejects_nonlinear_and_malformed() {
        assert!(parse_linear("Lp * tau_f")
            .unwrap_err()
            .contains("not linear"));
        assert!(parse_linear("1 / tau_f")
            .unwrap_err()
            .contains("not linear"));
        assert!(parse_linear("Xu +").is_err());
        assert!(parse_linear("(Xu").unwrap_err().contains(")"));
        assert!(parse_linear("Xu $ 2")
            .unwrap_err()
            .contains("unexpected character"));
        assert!(parse_linear("").is_err());
        assert!(parse_linear("Xu / 0").unwrap_err().contains("zero"));
    }

    proptest::proptest! {
        #[test]
        fn linear_combinations_round_trip(
            a in -1e3f64..1e3,
            b in -1e3f64..1e3,
            c in -1e3f64..1e3,
        ) {
            // Written the way a structure file would: `a*Xu - (b)*Zw + c`.
            let text = format!("{a:?}*Xu - ({b:?})*Zw + {c:?}");
            let form = parse_linear(&text).unwrap();
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * (1.0 + y.abs());
            proptest::prop_assert!(close(coefficient(&form, "Xu"), a));
            proptest::prop_assert!(close(coefficient(&form, "Zw"), -b));
            proptest::prop_assert!(close(form.constant, c));
        }
    }
}
