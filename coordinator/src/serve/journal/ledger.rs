//! The task ledger: a line per task id, with its robot, stations and the ticks of its stages.

use super::*;

/// A task's line in the ledger.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TaskRecord {
    /// The task's id, unique on the site.
    pub task: u64,
    /// The robot it was given to.
    pub robot: u32,
    /// The station to pick at.
    pub pick_station: u32,
    /// The dock to drop at.
    pub drop_station: u32,
    /// The tick it was assigned at.
    pub assigned_tick: u64,
    /// The tick the robot reached the pick station, if it has.
    pub picked_tick: Option<u64>,
    /// The tick the robot dropped the load (the task done), if it has.
    pub done_tick: Option<u64>,
}

/// The task a fleet event is about.
pub(super) fn task_of(event: &FleetEvent) -> u64 {
    match *event {
        FleetEvent::Assigned { task, .. } => task.id,
        FleetEvent::Picked { task, .. } | FleetEvent::Done { task, .. } => task,
    }
}

/// A task's ledger line after `event` at `tick`, from its line so far (`None` for a task
/// not yet in the ledger; a stage of a task never assigned gives `None`).
pub fn ledger_step(line: Option<TaskRecord>, tick: u64, event: &FleetEvent) -> Option<TaskRecord> {
    match *event {
        FleetEvent::Assigned { robot, task } => Some(TaskRecord {
            task: task.id,
            robot: robot as u32,
            pick_station: task.pick as u32,
            drop_station: task.drop as u32,
            assigned_tick: tick,
            picked_tick: None,
            done_tick: None,
        }),
        FleetEvent::Picked { .. } => line.map(|l| TaskRecord {
            picked_tick: Some(tick),
            ..l
        }),
        FleetEvent::Done { .. } => line.map(|l| TaskRecord {
            done_tick: Some(tick),
            ..l
        }),
    }
}
