//! The parameter table (paper Table 3) with the truth, the errors and the accuracy flags.

use super::{fmt, KEY_PARAMETERS};
use crate::report::html::{note, section, table, Cell, Mark};
use crate::report::inputs::ReportInputs;

/// The parameter table (paper Table 3) with truth and flags.
pub fn parameter_section(inputs: &ReportInputs) -> String {
    let Some(fit) = &inputs.summary.fit else {
        return section(
            "parameters",
            "Identified parameters",
            &note("No fit in this campaign."),
        );
    };
    let rows: Vec<Vec<Cell>> = fit
        .params
        .iter()
        .map(|p| {
            let free = p.status == "free";
            let cr_flag = free && p.cr_percent.is_none_or(|v| v > 20.0);
            let insensitivity_flag = free && p.insensitivity_percent.is_none_or(|v| v > 10.0);
            let key = KEY_PARAMETERS.contains(&p.name.as_str());
            let error_cell = match (p.error_percent, key) {
                (Some(e), true) => Cell::judged(format!("{e:+.1}"), e.abs() <= 10.0),
                (e, _) => Cell::plain(e.map_or("-".to_string(), |e| format!("{e:+.1}"))),
            };
            vec![
                Cell::name(if key {
                    format!("{} *", p.name)
                } else {
                    p.name.clone()
                }),
                Cell::plain(format!("{:.5}", p.value)),
                Cell::marked(
                    fmt(p.cr_percent, 2),
                    if cr_flag { Mark::Flag } else { Mark::Plain },
                ),
                Cell::marked(
                    fmt(p.insensitivity_percent, 2),
                    if insensitivity_flag {
                        Mark::Flag
                    } else {
                        Mark::Plain
                    },
                ),
                Cell::plain(fmt(p.truth, 5)),
                error_cell,
                Cell::plain(p.status.clone()),
                Cell::marked(
                    p.flags.join(", "),
                    if p.flags.is_empty() {
                        Mark::Plain
                    } else {
                        Mark::Flag
                    },
                ),
            ]
        })
        .collect();
    let content = note(&format!(
        "{} after reduction. CR: Cramér–Rao bound, insensitivity: both in % of |value| \
(guidelines ≤ 20 % and ≤ 10 %; orange: beyond). Truth: the simulator's linearization at hover \
mapped onto the structure; error = 100·(value − truth)/|truth|. * marks the parameters the \
fit issue requires within 10 % of the truth (green/red).",
        fit.structure
    )) + &table(
        &[
            "parameter",
            "value",
            "CR %",
            "insens. %",
            "truth",
            "error %",
            "status",
            "flags",
        ],
        &rows,
    );
    section(
        "parameters",
        "Identified parameters (paper Table 3)",
        &content,
    )
}
