//! Encoding and decoding the fleet's two busiest messages: an observation (30 neighbours, 10 of
//! them robots with 32-sample intents, as in a busy warehouse aisle) and an intent. Every
//! observation is encoded once by the coordinator and decoded once by its agent; every intent
//! the other way round, so both sit on the fleet's round trip (issue 4).
//!
//!     cargo bench -p schemas --bench codec

use criterion::{Criterion, criterion_group, criterion_main};
use schemas::{
    IntentMsg, Kind, Observation, P2, Perceived, Sample, VisibilityProfile, decode, encode,
};
use std::hint::black_box;

fn trajectory() -> Vec<Sample> {
    (1..=32)
        .map(|i| {
            let t = 0.25 * f64::from(i);
            Sample {
                t,
                p: P2(1.0 + t, 2.0 - 0.5 * t),
                sigma: 0.1666 + 0.05 * t,
            }
        })
        .collect()
}

fn observation() -> Observation {
    let neighbours = (0..30_u32)
        .map(|k| {
            let robot = k % 3 == 0;
            Perceived {
                id: if robot {
                    (1 << 32) + u64::from(k)
                } else {
                    u64::from(k)
                },
                kind: if robot { Kind::Robot } else { Kind::Human },
                p: P2(f64::from(k) * 0.7, -3.0 + f64::from(k % 7)),
                vel: P2(0.9, -0.2),
                radius: if robot { 0.3 } else { 0.35 },
                intent: robot.then(trajectory),
            }
        })
        .collect();
    Observation {
        robot_id: 7,
        seq: 1234,
        sim_time: 123.4,
        dt: 0.1,
        map_version: 1,
        p: P2(10.0, 4.0),
        heading: 0.3,
        vel: P2(0.8, 0.1),
        yaw_rate: 0.05,
        radius: 0.3,
        goal: Some(P2(40.0, 12.0)),
        task: None,
        neighbours,
        visibility: None,
        real: false,
    }
}

fn intent() -> IntentMsg {
    IntentMsg {
        robot_id: 7,
        obs_seq: 1234,
        stamp: 123.4,
        planner: "pgp+orca".into(),
        subgoal: P2(11.0, 4.5),
        trajectory: trajectory(),
    }
}

fn codec(c: &mut Criterion) {
    let obs = observation();
    let obs_bytes = encode(&obs);
    let int = intent();
    let int_bytes = encode(&int);
    let mut g = c.benchmark_group("codec");
    g.bench_function(format!("encode/observation-{}B", obs_bytes.len()), |b| {
        b.iter(|| encode(black_box(&obs)))
    });
    g.bench_function(format!("decode/observation-{}B", obs_bytes.len()), |b| {
        b.iter(|| decode::<Observation>(black_box(&obs_bytes)).expect("valid"))
    });
    // The same with a hallway robot's visibility profile (body occlusion on): 360 rays.
    let seeing = Observation {
        visibility: Some(VisibilityProfile {
            bearing0: 0.0,
            range: 10.0,
            ranges: (0..360).map(|k| 2.0 + (k % 37) as f32 * 0.2).collect(),
        }),
        ..obs.clone()
    };
    let seeing_bytes = encode(&seeing);
    g.bench_function(
        format!("decode/observation-with-visibility-{}B", seeing_bytes.len()),
        |b| b.iter(|| decode::<Observation>(black_box(&seeing_bytes)).expect("valid")),
    );
    g.bench_function(format!("encode/intent-{}B", int_bytes.len()), |b| {
        b.iter(|| encode(black_box(&int)))
    });
    g.bench_function(format!("decode/intent-{}B", int_bytes.len()), |b| {
        b.iter(|| decode::<IntentMsg>(black_box(&int_bytes)).expect("valid"))
    });
    g.finish();
}

criterion_group!(benches, codec);
criterion_main!(benches);
