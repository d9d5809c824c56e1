//! Structure-aware fuzzing of `schemas::decode` for every message type.
//!
//! Each case starts from a valid message (the samples in `common`, and the committed corpus in
//! `tests/fuzz-corpus/`), reads its MessagePack into a tree, mutates the tree (numbers replaced
//! by NaN, ±∞, 1e308, huge or negative integers; fields dropped, duplicated, renamed or given
//! another type; arrays emptied or grown past their limits; subtrees spliced in from other
//! messages; the version changed), writes it back, sometimes mutates the bytes too (flips,
//! truncation, insertion), and decodes it as every message type. A case fails if a decode
//! panics, or if a message that decodes does not encode and decode back to itself.
//!
//! `cargo test --release -p schemas --test fuzz` runs 20,000 cases (CI). The long run:
//!
//!     GAPFLEET_FUZZ_CASES=10000000 cargo test --release -p schemas --test fuzz -- --nocapture
//!
//! A failing input is written to `target/fuzz-crash-<case>.msgpack`; commit it to
//! `tests/fuzz-corpus/` once fixed, and every run replays it first.

mod common;

use common::*;
use schemas::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// SplitMix64: small, fast, seeded (the same cases every run).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn chance(&mut self, one_in: u64) -> bool {
        self.next().is_multiple_of(one_in)
    }
}

/// A MessagePack value.
#[derive(Debug, Clone)]
enum V {
    Nil,
    Bool(bool),
    Int(i64),
    UInt(u64),
    F32(f32),
    F64(f64),
    Str(String),
    Bin(Vec<u8>),
    Arr(Vec<V>),
    Map(Vec<(V, V)>),
}

/// Reads one value (None on anything this reader does not take: the mutators start from
/// well-formed messages only).
fn read(rd: &mut &[u8], depth: usize) -> Option<V> {
    use rmp::Marker;
    if depth > 64 {
        return None;
    }
    let marker = rmp::decode::read_marker(rd).ok()?;
    let take = |rd: &mut &[u8], n: usize| -> Option<Vec<u8>> {
        if rd.len() < n {
            return None;
        }
        let (head, tail) = rd.split_at(n);
        *rd = tail;
        Some(head.to_vec())
    };
    let be = |b: Vec<u8>| b.iter().fold(0u64, |acc, &x| (acc << 8) | u64::from(x));
    Some(match marker {
        Marker::Null => V::Nil,
        Marker::True => V::Bool(true),
        Marker::False => V::Bool(false),
        Marker::FixPos(n) => V::UInt(u64::from(n)),
        Marker::FixNeg(n) => V::Int(i64::from(n)),
        Marker::U8 => V::UInt(be(take(rd, 1)?)),
        Marker::U16 => V::UInt(be(take(rd, 2)?)),
        Marker::U32 => V::UInt(be(take(rd, 4)?)),
        Marker::U64 => V::UInt(be(take(rd, 8)?)),
        Marker::I8 => V::Int(i64::from(be(take(rd, 1)?) as u8 as i8)),
        Marker::I16 => V::Int(i64::from(be(take(rd, 2)?) as u16 as i16)),
        Marker::I32 => V::Int(i64::from(be(take(rd, 4)?) as u32 as i32)),
        Marker::I64 => V::Int(be(take(rd, 8)?) as i64),
        Marker::F32 => V::F32(f32::from_bits(be(take(rd, 4)?) as u32)),
        Marker::F64 => V::F64(f64::from_bits(be(take(rd, 8)?))),
        Marker::FixStr(n) => V::Str(String::from_utf8(take(rd, usize::from(n))?).ok()?),
        Marker::Str8 => {
            let n = be(take(rd, 1)?) as usize;
            V::Str(String::from_utf8(take(rd, n)?).ok()?)
        }
        Marker::Str16 => {
            let n = be(take(rd, 2)?) as usize;
            V::Str(String::from_utf8(take(rd, n)?).ok()?)
        }
        Marker::Str32 => {
            let n = be(take(rd, 4)?) as usize;
            V::Str(String::from_utf8(take(rd, n)?).ok()?)
        }
        Marker::Bin8 => {
            let n = be(take(rd, 1)?) as usize;
            V::Bin(take(rd, n)?)
        }
        Marker::Bin16 => {
            let n = be(take(rd, 2)?) as usize;
            V::Bin(take(rd, n)?)
        }
        Marker::FixArray(n) => V::Arr(items(rd, usize::from(n), depth)?),
        Marker::Array16 => {
            let n = be(take(rd, 2)?) as usize;
            V::Arr(items(rd, n, depth)?)
        }
        Marker::Array32 => {
            let n = be(take(rd, 4)?) as usize;
            V::Arr(items(rd, n, depth)?)
        }
        Marker::FixMap(n) => V::Map(entries(rd, usize::from(n), depth)?),
        Marker::Map16 => {
            let n = be(take(rd, 2)?) as usize;
            V::Map(entries(rd, n, depth)?)
        }
        Marker::Map32 => {
            let n = be(take(rd, 4)?) as usize;
            V::Map(entries(rd, n, depth)?)
        }
        _ => return None,
    })
}

fn items(rd: &mut &[u8], n: usize, depth: usize) -> Option<Vec<V>> {
    (0..n).map(|_| read(rd, depth + 1)).collect()
}

fn entries(rd: &mut &[u8], n: usize, depth: usize) -> Option<Vec<(V, V)>> {
    (0..n)
        .map(|_| Some((read(rd, depth + 1)?, read(rd, depth + 1)?)))
        .collect()
}

fn write(v: &V, out: &mut Vec<u8>) {
    use rmp::encode as e;
    // Writing into a Vec cannot fail.
    let _ = match v {
        V::Nil => e::write_nil(out).map_err(|_| ()),
        V::Bool(b) => e::write_bool(out, *b).map_err(|_| ()),
        V::Int(i) => e::write_sint(out, *i).map(|_| ()).map_err(|_| ()),
        V::UInt(u) => e::write_uint(out, *u).map(|_| ()).map_err(|_| ()),
        V::F32(f) => e::write_f32(out, *f).map_err(|_| ()),
        V::F64(f) => e::write_f64(out, *f).map_err(|_| ()),
        V::Str(s) => e::write_str(out, s).map_err(|_| ()),
        V::Bin(b) => e::write_bin(out, b).map_err(|_| ()),
        V::Arr(items) => {
            let _ = e::write_array_len(out, items.len() as u32);
            items.iter().for_each(|i| write(i, out));
            Ok(())
        }
        V::Map(entries) => {
            let _ = e::write_map_len(out, entries.len() as u32);
            for (k, v) in entries {
                write(k, out);
                write(v, out);
            }
            Ok(())
        }
    };
}

/// Every node of the tree, as a path of child indices (map entries count their value).
fn paths(v: &V, here: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    out.push(here.clone());
    match v {
        V::Arr(items) => {
            for (i, item) in items.iter().enumerate() {
                here.push(i);
                paths(item, here, out);
                here.pop();
            }
        }
        V::Map(entries) => {
            for (i, (_, value)) in entries.iter().enumerate() {
                here.push(i);
                paths(value, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn node<'a>(v: &'a mut V, path: &[usize]) -> &'a mut V {
    match (path.split_first(), v) {
        (None, v) => v,
        (Some((&i, rest)), V::Arr(items)) => node(&mut items[i], rest),
        (Some((&i, rest)), V::Map(entries)) => node(&mut entries[i].1, rest),
        (Some(_), v) => v,
    }
}

/// A value a decoder must survive in place of any other.
fn nasty(rng: &mut Rng) -> V {
    const FLOATS: [f64; 12] = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e308,
        -1e308,
        -0.0,
        5e-324,
        1e7,
        -1e7,
        1e10,
        0.0,
        -1.0,
    ];
    match rng.below(12) {
        0..=3 => V::F64(FLOATS[rng.below(FLOATS.len())]),
        4 => V::F32(f32::NAN),
        5 => V::UInt([u64::MAX, u64::from(u32::MAX) + 1, 4097, 1 << 53][rng.below(4)]),
        6 => V::Int([i64::MIN, -1, -4097][rng.below(3)]),
        7 => V::Str(["", "x", "polygon", "wall", "hold", "velocity", "v"][rng.below(7)].into()),
        8 => V::Str("é".repeat(rng.below(300))),
        9 => V::Nil,
        10 => V::Bool(rng.chance(2)),
        _ => V::Arr(Vec::new()),
    }
}

/// One structural mutation of `tree`; `donors` lend subtrees.
fn mutate(tree: &mut V, donors: &[V], rng: &mut Rng) {
    let mut all = Vec::new();
    paths(tree, &mut Vec::new(), &mut all);
    let at = all[rng.below(all.len())].clone();
    let target = node(tree, &at);
    match rng.below(8) {
        0 | 1 => *target = nasty(rng),
        2 => {
            // A subtree of another message.
            let donor = &donors[rng.below(donors.len())];
            let mut theirs = Vec::new();
            paths(donor, &mut Vec::new(), &mut theirs);
            let from = theirs[rng.below(theirs.len())].clone();
            let mut donor = donor.clone();
            *target = node(&mut donor, &from).clone();
        }
        3 => match &mut *target {
            V::Map(entries) if !entries.is_empty() => {
                let i = rng.below(entries.len());
                match rng.below(3) {
                    0 => {
                        entries.remove(i);
                    }
                    1 => {
                        let e = entries[i].clone();
                        entries.push(e);
                    }
                    _ => entries[i].0 = nasty(rng),
                }
            }
            V::Arr(items) if !items.is_empty() => match rng.below(3) {
                0 => items.truncate(rng.below(items.len())),
                1 => {
                    // Past every limit (the largest is 8,192 rays).
                    let first = items[0].clone();
                    let n = [2, 300, 5000, 9000][rng.below(4)];
                    items.extend(std::iter::repeat_n(first, n));
                }
                _ => items.reverse(),
            },
            other => *other = nasty(rng),
        },
        4 => {
            // A number nudged: off by one, negated, scaled.
            *target = match &*target {
                V::UInt(u) => V::UInt(u.wrapping_add(rng.next() % 3).wrapping_sub(1)),
                V::Int(i) => V::Int(i.wrapping_neg()),
                V::F64(f) => V::F64(*f * [1e6, -1.0, 1e-6, 1e300][rng.below(4)]),
                other => other.clone(),
            }
        }
        5 => *target = V::Map(vec![(V::Str("v".into()), V::UInt(rng.next() % 4))]),
        6 => {
            let copy = target.clone();
            *target = V::Arr(vec![copy; 1 + rng.below(3)]);
        }
        _ => {
            // The version, wherever it is.
            if let V::Map(entries) = tree
                && let Some(e) = entries
                    .iter_mut()
                    .find(|(k, _)| matches!(k, V::Str(s) if s == "v"))
            {
                e.1 = V::UInt(rng.next() % 4);
            }
        }
    }
}

/// Byte-level damage on top.
fn damage(bytes: &mut Vec<u8>, rng: &mut Rng) {
    if bytes.is_empty() {
        return;
    }
    match rng.below(4) {
        0 => {
            let at = rng.below(bytes.len());
            bytes[at] = rng.next() as u8;
        }
        1 => bytes.truncate(rng.below(bytes.len())),
        2 => {
            let at = rng.below(bytes.len());
            let junk: Vec<u8> = (0..1 + rng.below(8)).map(|_| rng.next() as u8).collect();
            bytes.splice(at..at, junk);
        }
        _ => {
            // A length header claiming far more than follows.
            let at = rng.below(bytes.len());
            bytes[at] = [0xdc, 0xdd, 0xde, 0xdf, 0xdb, 0xc6][rng.below(6)];
        }
    }
}

/// Decodes `bytes` as every message type; Err names the first problem (a panic included).
fn decode_all(bytes: &[u8]) -> Result<u32, String> {
    catch_unwind(AssertUnwindSafe(|| fuzzing::decode_as_every_type(bytes))).unwrap_or_else(
        |panic| {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                .unwrap_or_default();
            Err(format!("panicked: {what}"))
        },
    )
}

fn corpus_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-corpus")
}

/// The sample messages, by name.
fn samples() -> [(&'static str, Vec<u8>); 9] {
    [
        ("observation", encode(&observation())),
        ("intent", encode(&intent())),
        ("command", encode(&command())),
        ("task", encode(&task())),
        ("info", encode(&info())),
        ("fan", encode(&fan())),
        ("traffic", encode(&traffic())),
        ("metrics", encode(&metrics())),
        ("map", encode(&map())),
    ]
}

/// The files in `dir` (of the committed corpora), sorted; those named `*.msgpack` only when
/// `msgpack_only`.
fn files_in(dir: &std::path::Path, msgpack_only: bool) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files.retain(|f| !msgpack_only || f.extension().is_some_and(|e| e == "msgpack"));
    files
}

/// The seeds: every sample message, every file of the committed hand-made corpus, and every
/// input the coverage-guided fuzzer kept (`schemas/fuzz/corpus/`).
fn seeds() -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = samples().into_iter().map(|(_, b)| b).collect();
    let afl = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let files = files_in(&corpus_dir(), true)
        .into_iter()
        .chain(files_in(&afl, false));
    seeds.extend(files.filter_map(|f| std::fs::read(f).ok()));
    seeds
}

/// The AFL++ harness starts from the sample messages, written to `schemas/fuzz/seeds/`. They
/// are kept equal to the samples here; `GAPFLEET_WRITE_AFL_SEEDS=1` writes them anew.
#[test]
fn the_afl_seeds_are_the_sample_messages() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    let write = std::env::var("GAPFLEET_WRITE_AFL_SEEDS").is_ok_and(|v| v == "1");
    for (name, bytes) in samples() {
        let path = dir.join(format!("sample-{name}.msgpack"));
        if write {
            std::fs::write(&path, &bytes).expect("seed written");
        }
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            committed,
            bytes,
            "{} is stale: rerun with GAPFLEET_WRITE_AFL_SEEDS=1",
            path.display()
        );
    }
    assert_eq!(files_in(&dir, true).len(), 9, "only the samples are seeds");
}

#[test]
fn every_corpus_input_decodes_or_is_rejected_without_a_panic() {
    let seeds = seeds();
    assert!(seeds.len() >= 9 + 9, "the committed corpus is missing");
    for (i, bytes) in seeds.iter().enumerate() {
        decode_all(bytes).unwrap_or_else(|e| panic!("seed {i}: {e}"));
    }
    // The sample messages themselves decode as their own type.
    for bytes in &seeds[..9] {
        assert!(decode_all(bytes).expect("no failure") >= 1);
    }
}

#[test]
fn mutated_messages_never_panic_and_what_decodes_round_trips() {
    let cases: u64 = std::env::var("GAPFLEET_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let seed: u64 = std::env::var("GAPFLEET_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let trees: Vec<V> = seeds()
        .iter()
        .filter_map(|b| read(&mut b.as_slice(), 0))
        .collect();
    assert!(trees.len() >= 9, "every sample message reads as a tree");
    let mut rng = Rng(seed);
    let (mut decoded, mut bytes_total) = (0u64, 0u64);
    let started = std::time::Instant::now();
    let mut out = Vec::new();
    for case in 0..cases {
        let mut tree = trees[rng.below(trees.len())].clone();
        for _ in 0..1 + rng.below(4) {
            mutate(&mut tree, &trees, &mut rng);
        }
        out.clear();
        write(&tree, &mut out);
        if rng.chance(4) {
            damage(&mut out, &mut rng);
        }
        bytes_total += out.len() as u64;
        match decode_all(&out) {
            Ok(n) => decoded += u64::from(n > 0),
            Err(e) => {
                let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target");
                let file = dir.join(format!("fuzz-crash-{case}.msgpack"));
                let _ = std::fs::create_dir_all(&dir);
                let _ = std::fs::write(&file, &out);
                panic!(
                    "case {case} (seed {seed}): {e}; input saved to {}",
                    file.display()
                );
            }
        }
        if (case + 1).is_multiple_of(1_000_000) {
            println!(
                "{} cases, {decoded} decoded as some message, {:.0} s",
                case + 1,
                started.elapsed().as_secs_f64()
            );
        }
    }
    println!(
        "{cases} cases (seed {seed}): 0 failures; {decoded} decoded as some message \
         (the rest rejected); {:.1} MB decoded 9 ways in {:.1} s",
        bytes_total as f64 / 1e6,
        started.elapsed().as_secs_f64()
    );
    // The mutations keep some inputs valid: the fuzzer reaches past the first checks.
    assert!(decoded > cases / 50, "only {decoded} of {cases} decoded");
}
