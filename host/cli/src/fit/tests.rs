use super::*;
use sysid::fit::cost::PairBand;
use sysid::fit::synthetic::{exact_frf_document, SyntheticGrid};

const LAG: &str = r#"
name = "lag"
states = ["x"]
controls = ["lat"]
outputs = ["x"]
pairs = [{ output = "x", input = "lat" }]
[parameters]
a = -2.0
b = 3.0
[F.x]
x = "a"
[G.x]
lat = "b"
"#;

#[test]
fn fits_and_writes_model_json() {
    let directory = std::env::temp_dir().join(format!("sweephold-fit-{}", std::process::id()));
    fs::create_dir_all(&directory).unwrap();
    let structure_path = directory.join("lag.toml");
    fs::write(&structure_path, LAG).unwrap();
    let structure = ModelStructure::parse(LAG, "lag").unwrap();
    let truth = structure.model(&[-1.5, 2.0]).unwrap();
    let band = PairBand {
        input: "lat".into(),
        output: "x".into(),
        range: [0.2, 20.0],
    };
    let frf = exact_frf_document(&truth, &[band], SyntheticGrid::FitPoints(20));
    let frf_path = directory.join("frf.json");
    fs::write(&frf_path, serde_json::to_string(&frf).unwrap()).unwrap();
    let out = directory.join("model.json");
    let mut args = FitArgs {
        frf: frf_path,
        model: structure_path.clone(),
        out: Some(out.clone()),
        reduce: false,
        seed: 3,
        start_from: None,
        max_starts: 4,
        search: SearchArg::Local,
        points: 20,
        truth: None,
        constants: Vec::new(),
        trim_points: None,
        trim_balance: TrimBalanceArg::Hold,
        equation_error_start: false,
    };
    run(&args).unwrap();
    let document: ModelDocument = serde_json::from_str(&fs::read_to_string(&out).unwrap()).unwrap();
    assert!((document.parameter("a").unwrap() + 1.5).abs() < 1e-6);
    assert!((document.parameter("b").unwrap() - 2.0).abs() < 1e-6);

    // From an equation-error start too (the state is measured: x is an output).
    args.equation_error_start = true;
    args.max_starts = 2;
    run(&args).unwrap();
    let document: ModelDocument = serde_json::from_str(&fs::read_to_string(&out).unwrap()).unwrap();
    assert!((document.parameter("a").unwrap() + 1.5).abs() < 1e-6);
    args.equation_error_start = false;

    // A malformed structure file is reported with its line.
    fs::write(&structure_path, LAG.replace("lat = \"b\"", "lat = \"Zq\"")).unwrap();
    let error = run(&args).unwrap_err().to_string();
    assert!(
        error.contains("line 13") && error.contains("undefined parameter `Zq`"),
        "{error}"
    );
    fs::remove_dir_all(&directory).ok();
}
