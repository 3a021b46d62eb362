//! The campaign folder: its layout and the documents in it. The campaign writes them, the
//! report reads them (`sweephold report DIR` from the folder alone): `summary.json`
//! ([`summary`]), `truth-model9.json` ([`truth_model`]), `verify.json` ([`verification`]),
//! the stage names `summary.json` keys its timings by ([`stage`]), where each file lies
//! ([`files`]), and what the report draws from the dumps ([`flown`]), which a campaign
//! hands over as it decoded it; `model9.json`'s aircraft constants with their σ
//! ([`aircraft_constants`]). `sweephold identify` writes a folder of the same documents
//! without the truth, its own `summary.json` ([`identify_summary`]).

pub mod aircraft_constants;
pub mod files;
pub mod flown;
pub mod identify_summary;
pub mod priors;
pub mod stage;
pub mod summary;
pub mod truth_model;
pub mod verification;
