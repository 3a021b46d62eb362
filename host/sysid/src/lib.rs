//! Frequency-domain system identification in the manner of CIFER: frequency responses
//! (FRESPID, MISOSA, COMPOSITE) and state-space fits with accuracy metrics (DERIVID,
//! VERIFY).

pub mod document;
pub mod fit;
pub mod frf;
pub mod models;
pub mod random;
