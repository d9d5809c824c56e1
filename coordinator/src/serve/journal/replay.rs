//! Re-running a journal in-process: from where it begins (`gapfleet replay`, checking
//! fingerprints, snapshots and the ledger; tick 0, or the snapshot a recovered journal begins
//! at), or from its newest snapshot (a restart).

use super::*;

/// A fingerprint of the world: FNV-1a over the bits of the simulated time, every robot's
/// pose, velocity, held flag, tasks done and path length, and every person's position and
/// velocity.
pub fn fingerprint(fleet: &Fleet) -> u64 {
    let held: Vec<bool> = (0..fleet.robots()).map(|i| fleet.is_held(i)).collect();
    fingerprint_with_held(fleet, &held)
}

/// [`fingerprint`] with the robots' held flags taken from `held` rather than the fleet: the
/// world as the journal's records leave it, when flags changed since the last tick are in no
/// record yet.
pub fn fingerprint_with_held(fleet: &Fleet, held: &[bool]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    eat(fleet.world.time.to_bits());
    for (i, r) in fleet.world.robots.iter().enumerate() {
        let s = &r.state;
        for x in [
            s.position.x,
            s.position.y,
            s.velocity.x,
            s.velocity.y,
            s.heading,
        ] {
            eat(x.to_bits());
        }
        eat(u64::from(held.get(i).copied().unwrap_or(false)));
        eat(fleet.tasks_done(i));
        eat(fleet.metrics(i).path_length_m.to_bits());
    }
    let crowd = &fleet.world.humans.crowd;
    for i in 0..crowd.len() {
        for x in [
            crowd.positions[i].x,
            crowd.positions[i].y,
            crowd.velocities[i].x,
            crowd.velocities[i].y,
        ] {
            eat(x.to_bits());
        }
    }
    h
}

/// Tasks done by the whole fleet.
fn tasks_done(fleet: &Fleet) -> u64 {
    (0..fleet.robots()).map(|i| fleet.tasks_done(i)).sum()
}

/// What a replay found.
#[derive(Debug)]
pub struct Replayed {
    /// The tick it started from: 0, or the restored snapshot's (the journal's start snapshot
    /// included).
    pub from: u64,
    /// Ticks the run is at after it: the journal's (those re-run are `ticks - from`).
    pub ticks: u64,
    /// The world's fingerprint after them.
    pub fingerprint: u64,
    /// Fingerprints checked on the way (every [`FINGERPRINT_EVERY`] ticks), all equal.
    pub checked: u64,
    /// Snapshots passed on the way and found equal to the replayed fleet, byte for byte.
    pub snapshots_checked: u64,
    /// Ledger lines found equal to the replay's (a replay from where the journal begins checks
    /// them all).
    pub tasks_checked: u64,
    /// Tasks done.
    pub tasks_done: u64,
    /// The fleet at the end.
    pub fleet: Fleet,
}

/// Re-runs a recorded run in-process from where its journal begins (tick 0, or its start
/// snapshot): builds its scenario, applies each tick's held flags, intents and commands, steps
/// and dispatches as the coordinator did. A fingerprint or snapshot that differs from the
/// recorded one is an error naming the tick.
pub fn replay(
    recorded: &Recorded,
    on_tick: impl FnMut(&Fleet, &[FleetEvent]),
) -> Result<Replayed, JournalError> {
    let fleet = match &recorded.start {
        Some((at, bytes)) => {
            let scenario = recorded.header.scenario.scenario()?;
            Fleet::restore(&scenario, bytes).map_err(|e| {
                JournalError::Record(format!(
                    "the snapshot the journal begins at (tick {at}): {e}"
                ))
            })?
        }
        None => new_fleet(recorded)?,
    };
    run_inputs(fleet, recorded.first_tick(), recorded, true, on_tick)
}

/// The run's state at the end of its journal, for a restart: the newest snapshot restored,
/// then the ticks after it re-run (all of them if there is no snapshot, or none restores).
pub fn resume(recorded: &Recorded) -> Result<Replayed, JournalError> {
    let scenario = recorded.header.scenario.scenario()?;
    let ticks = recorded.ticks_run();
    for (at, bytes) in recorded.snapshots.iter().rev() {
        if *at > ticks || *at < recorded.first_tick() {
            tracing::warn!(at, ticks, "snapshot past the journal's ticks: not used");
            continue;
        }
        match Fleet::restore(&scenario, bytes) {
            Ok(fleet) => return run_inputs(fleet, *at, recorded, false, |_, _| {}),
            Err(e) => tracing::warn!(at, "snapshot not used: {e}"),
        }
    }
    replay(recorded, |_, _| {})
}

/// A new fleet as the run began.
fn new_fleet(recorded: &Recorded) -> Result<Fleet, JournalError> {
    let scenario = recorded.header.scenario.scenario()?;
    let mut fleet = Fleet::new(&scenario).map_err(|e| JournalError::Scenario(e.to_string()))?;
    fleet.share_intents = recorded.header.share_intents;
    for &robot in &recorded.header.live {
        if robot as usize >= fleet.robots() {
            return Err(JournalError::Record(format!(
                "live robot {robot} of {}",
                fleet.robots()
            )));
        }
        fleet.set_external(robot as usize, true);
    }
    fleet.set_traffic_policy(recorded.header.policy());
    Ok(fleet)
}

/// `fleet` after `from` ticks, on through the rest of the journal.
fn run_inputs(
    mut fleet: Fleet,
    from: u64,
    recorded: &Recorded,
    check_snapshots: bool,
    mut on_tick: impl FnMut(&Fleet, &[FleetEvent]),
) -> Result<Replayed, JournalError> {
    // Held flags start as a new fleet's (none held) or the snapshot's; the first tick's record
    // holds the coordinator's holding every robot without an agent.
    let n = fleet.robots();
    let scenario = recorded.header.scenario.scenario()?;
    let mut snapshots = recorded.snapshots.iter().peekable();
    let (mut checked, mut snapshots_checked) = (0, 0);
    let mut commands = vec![agent::model::Command::STOP; n];
    // The ledger as the replay makes it (from where the journal begins only: the writer began
    // it there too; a later snapshot's tasks began before it).
    let mut ledger = std::collections::BTreeMap::<u64, TaskRecord>::new();
    let first = recorded.first_tick();
    let skip = from.checked_sub(first).ok_or_else(|| {
        JournalError::State(format!(
            "tick {from} is before the journal's first, {first}"
        ))
    })?;
    for (k, input) in (first..).zip(&recorded.ticks).skip(skip as usize) {
        if input.tick != k {
            return Err(JournalError::State(format!(
                "tick {} is missing (the record after it is tick {})",
                k, input.tick
            )));
        }
        for &(robot, held) in &input.held {
            if robot as usize >= n {
                return Err(JournalError::Record(format!("robot {robot} of {n}")));
            }
            fleet.set_held(robot as usize, held);
        }
        for intent in &input.intents {
            intent.apply(&mut fleet)?;
        }
        for i in 0..n {
            fleet.set_layer_held(i, false);
        }
        for &robot in &input.layer_held {
            if robot as usize >= n {
                return Err(JournalError::Record(format!("robot {robot} of {n}")));
            }
            fleet.set_layer_held(robot as usize, true);
        }
        for &(robot, state) in &input.placed {
            if robot as usize >= n {
                return Err(JournalError::Record(format!("robot {robot} of {n}")));
            }
            place(&mut fleet, robot as usize, &state);
        }
        commands.fill(agent::model::Command::STOP);
        for &(robot, motion) in &input.commands {
            let slot = commands
                .get_mut(robot as usize)
                .ok_or_else(|| JournalError::Record(format!("robot {robot} of {n}")))?;
            *slot = wire::command(motion);
        }
        let mut events = fleet.step(&commands);
        events.extend(fleet.dispatch());
        on_tick(&fleet, &events);
        for event in &events {
            let id = task_of(event);
            if let Some(line) = ledger_step(ledger.remove(&id), input.tick, event) {
                ledger.insert(id, line);
            }
        }
        if let Some(recorded_print) = input.fingerprint {
            let now = fingerprint(&fleet);
            if now != recorded_print {
                return Err(JournalError::State(format!(
                    "the replay left the recorded run at tick {}: fingerprint {now:016x}, recorded {recorded_print:016x}",
                    input.tick
                )));
            }
            checked += 1;
        }
        let ran = k + 1;
        while snapshots.next_if(|(at, _)| *at < ran).is_some() {}
        if check_snapshots && let Some((_, bytes)) = snapshots.next_if(|(at, _)| *at == ran) {
            same_as_snapshot(&fleet, &scenario, bytes, ran)?;
            snapshots_checked += 1;
        }
    }
    let print = fingerprint(&fleet);
    if let Some(end) = &recorded.end
        && end.ticks == recorded.ticks_run()
        && end.fingerprint != print
    {
        return Err(JournalError::State(format!(
            "the replay ended on fingerprint {print:016x}, the run on {:016x}",
            end.fingerprint
        )));
    }
    let mut tasks_checked = 0;
    if from == first {
        for line in &recorded.tasks {
            let replayed = ledger.get(&line.task);
            if replayed != Some(line) {
                return Err(JournalError::State(format!(
                    "the ledger's task {} is {line:?}; the replay made it {replayed:?}",
                    line.task
                )));
            }
            tasks_checked += 1;
        }
    }
    Ok(Replayed {
        from,
        ticks: recorded.ticks_run(),
        fingerprint: print,
        checked,
        snapshots_checked,
        tasks_checked,
        tasks_done: tasks_done(&fleet),
        fleet,
    })
}

/// Whether `fleet`, `ran` ticks into the replay, is the snapshot taken then, byte for byte.
/// The human-impact measurement a dashboard attaches is left out of both: it measures the
/// run (a shadow crowd) without changing it, and a replay attaches none.
fn same_as_snapshot(
    fleet: &Fleet,
    scenario: &world_sim::scenario::Scenario,
    bytes: &[u8],
    ran: u64,
) -> Result<(), JournalError> {
    let mut stored = Fleet::restore(scenario, bytes)
        .map_err(|e| JournalError::Record(format!("snapshot at tick {ran}: {e}")))?;
    stored.stop_measuring_human_impact();
    let mut replayed = fleet.clone();
    replayed.stop_measuring_human_impact();
    let (a, b) = (stored.snapshot(), replayed.snapshot());
    if a != b {
        let at = a.iter().zip(&b).position(|(x, y)| x != y);
        return Err(JournalError::State(format!(
            "the replay left the recorded run by tick {ran}: its state differs from the \
             snapshot taken then ({} and {} bytes, first difference at byte {})",
            b.len(),
            a.len(),
            at.map_or("(the end of the shorter)".to_owned(), |i| i.to_string())
        )));
    }
    Ok(())
}

/// Puts real robot `i` where its agent reported it, as the coordinator does before a step.
pub fn place(fleet: &mut Fleet, i: usize, state: &schemas::RobotState) {
    fleet.place(
        i,
        wire::vec(state.p),
        state.heading,
        wire::vec(state.vel),
        state.yaw_rate,
    );
}
