//! The robot table: one row per robot, robots in trouble first, as a Markdown document.
//!
//! Why a text document and not Rerun's dataframe view: the dataframe view lists raw component
//! columns per entity and time, which cannot be sorted by trouble, formatted with units or
//! hold a row that mixes a robot's state with its measurements without one entity per cell;
//! a Markdown table logged on the timeline is compact, legible at 100 robots, and scrubbing the
//! time line shows the table as it was.

use crate::RobotRow;
use std::fmt::Write as _;

/// The table as Markdown: robots in trouble (crashed, gone, stuck, touched someone) first,
/// then by id.
pub fn markdown(rows: &[RobotRow]) -> String {
    let mut order: Vec<&RobotRow> = rows.iter().collect();
    order.sort_by_key(|r| (!r.trouble, r.id));
    let troubled = rows.iter().filter(|r| r.trouble).count();
    let mut out = format!(
        "**{} robots, {troubled} in trouble** (first)\n\n\
         | robot | planner | state | tasks | contacts | SVR | closest person | share of people's delay |\n\
         |---:|---|---|---:|---:|---:|---:|---:|\n",
        rows.len()
    );
    let dash = || "–".to_owned();
    for r in order {
        let state = if r.trouble {
            format!("**{}**", r.state)
        } else {
            r.state.clone()
        };
        let closest = r
            .closest_person_m
            .map_or_else(dash, |d| format!("{d:.1} m"));
        let share = r
            .delay_share
            // A robot can save people a little time (a negative share); rounded to zero it
            // reads 0 %, not -0 %.
            .map_or_else(dash, |s| format!("{:.0} %", (100.0 * s).round() + 0.0));
        let _ = writeln!(
            out,
            "| {} | {} | {state} | {} | {} | {:.2} | {closest} | {share} |",
            r.id, r.planner, r.tasks_done, r.contacts, r.svr
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(id: u32, state: &str, trouble: bool) -> RobotRow {
        RobotRow {
            id,
            planner: "pgp+orca".into(),
            state: state.into(),
            trouble,
            tasks_done: u64::from(id),
            contacts: 0,
            svr: 0.125,
            closest_person_m: (id != 2).then_some(1.25),
            delay_share: (id == 1).then_some(0.5),
        }
    }

    /// Robots in trouble come first and in bold; missing values show as a dash.
    #[test]
    fn robots_in_trouble_come_first() {
        let md = markdown(&[
            row(0, "to pick", false),
            row(1, "idle", false),
            row(2, "stuck", true),
        ]);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines[0], "**3 robots, 1 in trouble** (first)");
        assert!(
            lines[4].starts_with("| 2 | pgp+orca | **stuck** | 2 | 0 | 0.12 | – | – |"),
            "{md}"
        );
        assert!(lines[5].starts_with("| 0 |"), "{md}");
        assert_eq!(
            lines[6],
            "| 1 | pgp+orca | idle | 1 | 0 | 0.12 | 1.2 m | 50 % |"
        );
    }
}
