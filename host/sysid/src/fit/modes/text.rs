//! Eigenvalues as text, for the reduction's notes and every table that shows a mode.

/// `re ± im j` of an eigenvalue record.
pub fn eigenvalue_text(eigenvalue: [f64; 2]) -> String {
    if eigenvalue[1] == 0.0 {
        format!("{:.4}", eigenvalue[0])
    } else {
        format!("{:.4} ± {:.4}j", eigenvalue[0], eigenvalue[1])
    }
}
