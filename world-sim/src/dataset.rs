//! Recorded pedestrians: the OpenTraj `obsmat.txt` format (ETH, UCY and the other sequences of
//! that collection) with its `map.xml` obstacles, interpolated from the annotation rate to any
//! simulation step.
//!
//! `obsmat.txt` holds one observation per line, whitespace separated:
//! `frame pedestrian pos_x pos_z pos_y v_x v_z v_y` (metres, m/s; the z columns are unused).
//! Consecutive annotations of one pedestrian are a fixed number of video frames apart (ETH 6,
//! UCY 10), which the loader infers; they are `sample_dt` seconds apart (2.5 fps: 0.4 s).

use agent::math::{Real, Vec2};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The annotation interval of the OpenTraj sequences (2.5 fps).
pub const SAMPLE_DT: Real = 0.4;

/// Why a recording could not be loaded. Line numbers count from 1.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// One line of `obsmat.txt` is malformed.
    #[error("{path}:{line}: {message}")]
    Line {
        /// The file.
        path: PathBuf,
        /// The line number.
        line: usize,
        /// What is wrong with it.
        message: String,
    },
    /// The file parsed but is unusable as a whole.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// `map.xml` is not an obstacle file.
    #[error("{path}: {source}")]
    Map {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        source: MapXmlError,
    },
}

/// Why an OpenTraj `map.xml` could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MapXmlError {
    /// Not XML at all.
    #[error("not valid XML: {0}")]
    Xml(#[from] roxmltree::Error),
    /// A `<Line>` lacks one of its coordinates.
    #[error("line {line}: <Line> without attribute {name}")]
    Missing {
        /// The text line of the element.
        line: u32,
        /// The attribute.
        name: &'static str,
    },
    /// A coordinate is not a finite number.
    #[error("line {line}: attribute {name}={raw:?} is not a finite number")]
    NotFinite {
        /// The text line of the element.
        line: u32,
        /// The attribute.
        name: &'static str,
        /// Its text.
        raw: String,
    },
}

/// One annotated position of a pedestrian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Seconds since the recording's first annotated frame.
    pub t: Real,
    /// Position (m).
    pub position: Vec2,
    /// Velocity as annotated (m/s).
    pub velocity: Vec2,
}

/// One pedestrian's annotations, in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// The pedestrian id of the file.
    pub id: u64,
    /// At least one sample, strictly increasing in time.
    pub samples: Vec<Sample>,
}

impl Track {
    /// First annotated time.
    pub fn start(&self) -> Real {
        self.samples[0].t
    }

    /// Last annotated time.
    pub fn end(&self) -> Real {
        self.samples[self.samples.len() - 1].t
    }

    /// Position and velocity at `t`, linearly interpolated between annotations; `None` before
    /// the first or after the last one.
    pub fn state_at(&self, t: Real) -> Option<(Vec2, Vec2)> {
        if t < self.start() - 1e-9 || t > self.end() + 1e-9 {
            return None;
        }
        let i = self.samples.partition_point(|s| s.t <= t);
        if i == 0 {
            let s = self.samples[0];
            return Some((s.position, s.velocity));
        }
        let a = self.samples[i - 1];
        let Some(b) = self.samples.get(i) else {
            return Some((a.position, a.velocity));
        };
        let w = (t - a.t) / (b.t - a.t);
        Some((
            a.position + (b.position - a.position) * w,
            a.velocity + (b.velocity - a.velocity) * w,
        ))
    }

    /// Length of the annotated path between samples `from` and `to` (inclusive indices).
    pub fn path_length(&self, from: usize, to: usize) -> Real {
        self.samples[from..=to]
            .windows(2)
            .map(|w| (w[1].position - w[0].position).norm())
            .sum()
    }
}

/// A recorded crowd: every pedestrian's track and the scene's obstacle lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Where it came from (the sequence folder's name).
    pub name: String,
    /// Tracks sorted by pedestrian id.
    pub tracks: Vec<Track>,
    /// Static obstacle lines from `map.xml` (empty when there is none).
    pub walls: Vec<(Vec2, Vec2)>,
    /// Where people go: `destinations.txt`, or, for a sequence without one or whose file does
    /// not fit its tracks ([`destination_fit`] below [`MIN_DESTINATION_FIT`]), the tracks' end
    /// points clustered ([`cluster_destinations`]). foIGP's mixtures have one intent per
    /// destination.
    pub destinations: Vec<Vec2>,
    /// Whether `destinations` came from the file or from clustering.
    pub destinations_from_file: bool,
    /// [`destination_fit`] of `destinations`.
    pub destinations_fit: Real,
    /// The fit of a `destinations.txt` that was set aside for not fitting the tracks.
    pub rejected_destinations_fit: Option<Real>,
}

/// A `destinations.txt` is used only if at least this share of the tracks' steps heads
/// within 45° of the destination the track ends nearest to: "people walk towards where they
/// end up". The recorded sequences: seq_eth's file 0.95 (its end points clustered 0.92);
/// zara01's file 0.41, its end points clustered 0.92 (that file is in another frame: its
/// tracks run along y from 5 to 21 m, its destinations lie at y = −15, −2, 5 and 10).
pub const MIN_DESTINATION_FIT: Real = 0.5;

/// The share of the tracks' steps (of at least 0.1 m, at least 1 m from the destination)
/// that head within 45° of the destination the track ends nearest to; 0 without steps or
/// destinations.
pub fn destination_fit(tracks: &[Track], destinations: &[Vec2]) -> Real {
    let (mut steps, mut towards) = (0usize, 0usize);
    for track in tracks {
        let Some(end) = track.samples.last().map(|s| s.position) else {
            continue;
        };
        let Some(goal) = destinations.iter().min_by(|a, b| {
            (*a - end)
                .norm_squared()
                .total_cmp(&(*b - end).norm_squared())
        }) else {
            return 0.0;
        };
        for w in track.samples.windows(2) {
            let step = w[1].position - w[0].position;
            let to = goal - w[0].position;
            if step.norm() < 0.1 || to.norm() < 1.0 {
                continue;
            }
            steps += 1;
            if step.dot(&to) >= step.norm() * to.norm() * std::f64::consts::FRAC_1_SQRT_2 {
                towards += 1;
            }
        }
    }
    if steps == 0 {
        0.0
    } else {
        towards as Real / steps as Real
    }
}

/// How many destinations [`cluster_destinations`] finds: as many as each recorded sequence's
/// `destinations.txt` lists (4).
pub const CLUSTERED_DESTINATIONS: usize = 4;

/// Destinations for a sequence without `destinations.txt`: the tracks' last positions in
/// `k` clusters (k-means, Lloyd's iterations to a fixed point, seeded deterministically by
/// farthest-point selection from the first track's end). Fewer than `k` distinct end points
/// give one destination each.
pub fn cluster_destinations(tracks: &[Track], k: usize) -> Vec<Vec2> {
    let ends: Vec<Vec2> = tracks
        .iter()
        .filter_map(|t| t.samples.last().map(|s| s.position))
        .collect();
    let Some(&first) = ends.first() else {
        return Vec::new();
    };
    let nearest = |p: &Vec2, centres: &[Vec2]| -> (usize, Real) {
        centres
            .iter()
            .enumerate()
            .map(|(i, c)| (i, (p - c).norm_squared()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("at least one centre")
    };
    let mut centres = vec![first];
    while centres.len() < k {
        let (far, d2) = ends
            .iter()
            .map(|p| nearest(p, &centres).1)
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .expect("ends is not empty");
        if d2 <= 0.0 {
            break;
        }
        centres.push(ends[far]);
    }
    for _ in 0..1000 {
        let mut sums = vec![(Vec2::zeros(), 0usize); centres.len()];
        for p in &ends {
            let (i, _) = nearest(p, &centres);
            sums[i].0 += p;
            sums[i].1 += 1;
        }
        let next: Vec<Vec2> = sums
            .iter()
            .zip(&centres)
            .map(|(&(sum, n), &c)| if n > 0 { sum / n as Real } else { c })
            .collect();
        if next == centres {
            break;
        }
        centres = next;
    }
    centres
}

/// `destinations.txt`: one `x y` pair per line (blank lines ignored).
pub fn parse_destinations(text: &str) -> Result<Vec<Vec2>, ObsmatError> {
    let mut out = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        let fail = |message: String| ObsmatError {
            line: index + 1,
            message,
        };
        if fields.len() != 2 {
            return Err(fail(format!(
                "expected 2 columns (x y), found {}",
                fields.len()
            )));
        }
        let mut xy = [0.0; 2];
        for (k, field) in fields.iter().enumerate() {
            xy[k] = field
                .parse::<Real>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| fail(format!("column {}: not a finite number: {field:?}", k + 1)))?;
        }
        out.push(Vec2::new(xy[0], xy[1]));
    }
    Ok(out)
}

impl Recording {
    /// Loads a sequence folder: `obsmat.txt` (required) and `map.xml` (optional).
    pub fn load(dir: &Path) -> Result<Self, DatasetError> {
        let obsmat = dir.join("obsmat.txt");
        let text = read(&obsmat)?;
        let tracks = parse_obsmat(&text, SAMPLE_DT).map_err(|e| e.at(&obsmat))?;
        let map = dir.join("map.xml");
        let walls = if map.exists() {
            parse_map_xml(&read(&map)?).map_err(|source| DatasetError::Map { path: map, source })?
        } else {
            Vec::new()
        };
        let name = dir.file_name().map_or_else(
            || dir.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let listed = dir.join("destinations.txt");
        let mut rejected_destinations_fit = None;
        let mut from_file = None;
        if listed.exists() {
            let text = read(&listed)?;
            let destinations = parse_destinations(&text).map_err(|e| e.at(&listed))?;
            let fit = destination_fit(&tracks, &destinations);
            if fit >= MIN_DESTINATION_FIT {
                from_file = Some((destinations, fit));
            } else {
                rejected_destinations_fit = Some(fit);
            }
        }
        let destinations_from_file = from_file.is_some();
        let (destinations, destinations_fit) = from_file.unwrap_or_else(|| {
            let clustered = cluster_destinations(&tracks, CLUSTERED_DESTINATIONS);
            let fit = destination_fit(&tracks, &clustered);
            (clustered, fit)
        });
        Ok(Self {
            name,
            tracks,
            walls,
            destinations,
            destinations_from_file,
            destinations_fit,
            rejected_destinations_fit,
        })
    }

    /// The track of pedestrian `id`.
    pub fn track(&self, id: u64) -> Option<&Track> {
        self.tracks
            .binary_search_by_key(&id, |t| t.id)
            .ok()
            .map(|i| &self.tracks[i])
    }

    /// Everyone present at `t` except `skip`: (id, position, velocity), by id.
    pub fn people_at(
        &self,
        t: Real,
        skip: Option<u64>,
    ) -> impl Iterator<Item = (u64, Vec2, Vec2)> + '_ {
        self.tracks
            .iter()
            .filter(move |track| Some(track.id) != skip)
            .filter_map(move |track| track.state_at(t).map(|(p, v)| (track.id, p, v)))
    }

    /// The last annotated time of the whole recording.
    pub fn end(&self) -> Real {
        self.tracks.iter().map(Track::end).fold(0.0, Real::max)
    }
}

fn read(path: &Path) -> Result<String, DatasetError> {
    std::fs::read_to_string(path).map_err(|source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A parse error before the file name is known.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsmatError {
    /// Line number (from 1), or 0 for the file as a whole.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl ObsmatError {
    fn at(self, path: &Path) -> DatasetError {
        let path = path.to_path_buf();
        match self.line {
            0 => DatasetError::File {
                path,
                message: self.message,
            },
            line => DatasetError::Line {
                path,
                line,
                message: self.message,
            },
        }
    }
}

/// Parses `obsmat.txt` text into tracks; annotations `sample_dt` seconds apart.
pub fn parse_obsmat(text: &str, sample_dt: Real) -> Result<Vec<Track>, ObsmatError> {
    let fail = |line: usize, message: String| ObsmatError { line, message };
    // (frame, position, velocity) per pedestrian.
    let mut raw: BTreeMap<u64, Vec<(u64, Vec2, Vec2, usize)>> = BTreeMap::new();
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        if fields.len() != 8 {
            return Err(fail(
                number,
                format!(
                    "expected 8 columns (frame pedestrian pos_x pos_z pos_y v_x v_z v_y), found {}",
                    fields.len()
                ),
            ));
        }
        let mut values = [0.0; 8];
        for (k, field) in fields.iter().enumerate() {
            let v: Real = field
                .parse()
                .map_err(|_| fail(number, format!("column {}: not a number: {field:?}", k + 1)))?;
            if !v.is_finite() {
                return Err(fail(
                    number,
                    format!("column {}: not finite: {field:?}", k + 1),
                ));
            }
            values[k] = v;
        }
        let whole = |v: Real, what: &str| {
            if v >= 0.0 && v.fract() == 0.0 && v < 1e15 {
                Ok(v as u64)
            } else {
                Err(fail(
                    number,
                    format!("{what} must be a non-negative integer, got {v}"),
                ))
            }
        };
        let frame = whole(values[0], "frame number")?;
        let id = whole(values[1], "pedestrian id")?;
        let position = Vec2::new(values[2], values[4]);
        let velocity = Vec2::new(values[5], values[7]);
        raw.entry(id)
            .or_default()
            .push((frame, position, velocity, number));
    }
    if raw.is_empty() {
        return Err(fail(0, "no observations".into()));
    }
    let mut gaps: BTreeMap<u64, usize> = BTreeMap::new();
    for obs in raw.values_mut() {
        obs.sort_by_key(|o| o.0);
        for w in obs.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(fail(
                    w[1].3,
                    format!(
                        "pedestrian annotated twice in frame {} (also line {})",
                        w[1].0, w[0].3
                    ),
                ));
            }
            *gaps.entry(w[1].0 - w[0].0).or_default() += 1;
        }
    }
    // The annotation step in frames: the most common gap (ties: the smaller).
    let step = gaps
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
        .map_or(1, |(gap, _)| *gap);
    let first = raw.values().map(|o| o[0].0).min().unwrap_or(0);
    let tracks = raw
        .into_iter()
        .map(|(id, obs)| Track {
            id,
            samples: obs
                .into_iter()
                .map(|(frame, position, velocity, _)| Sample {
                    t: (frame - first) as Real / step as Real * sample_dt,
                    position,
                    velocity,
                })
                .collect(),
        })
        .collect();
    Ok(tracks)
}

/// The `<Line x1 y1 x2 y2>` elements of an OpenTraj `map.xml`, in world metres.
pub fn parse_map_xml(text: &str) -> Result<Vec<(Vec2, Vec2)>, MapXmlError> {
    let doc = roxmltree::Document::parse(text)?;
    let mut walls = Vec::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("Line")) {
        let line = doc.text_pos_at(node.range().start).row;
        let attr = |name: &'static str| -> Result<Real, MapXmlError> {
            let raw = node
                .attribute(name)
                .ok_or(MapXmlError::Missing { line, name })?;
            raw.trim()
                .parse::<Real>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| MapXmlError::NotFinite {
                    line,
                    name,
                    raw: raw.to_owned(),
                })
        };
        let a = Vec2::new(attr("x1")?, attr("y1")?);
        let b = Vec2::new(attr("x2")?, attr("y2")?);
        if (b - a).norm() > 1e-9 {
            walls.push((a, b));
        }
    }
    Ok(walls)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dataset(path: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("datasets")
            .join(path)
    }

    #[test]
    fn loads_eth_and_zara01() {
        let eth = Recording::load(&dataset("ETH/seq_eth")).expect("seq_eth loads");
        assert_eq!(eth.name, "seq_eth");
        assert_eq!(eth.tracks.len(), 360);
        assert_eq!(eth.walls.len(), 4);
        let first = eth.track(1).expect("pedestrian 1");
        // Frames 780, 786, … are 6 video frames = 0.4 s apart; frame 780 is the first.
        assert_eq!(first.samples[0].t, 0.0);
        assert!((first.samples[1].t - 0.4).abs() < 1e-12);
        assert_eq!(first.samples[0].position, Vec2::new(8.4568443, 3.5880664));
        assert_eq!(first.samples[0].velocity, Vec2::new(1.6717144, 0.17629183));
        let zara = Recording::load(&dataset("UCY/zara01")).expect("zara01 loads");
        assert_eq!(zara.tracks.len(), 148);
        assert_eq!(zara.walls.len(), 7);
        let p1 = zara.track(1).expect("pedestrian 1");
        assert!((p1.samples[1].t - 0.4).abs() < 1e-12, "10 frames = 0.4 s");
        // 5024 observations in all.
        let total: usize = zara.tracks.iter().map(|t| t.samples.len()).sum();
        assert_eq!(total, 5024);
    }

    #[test]
    fn interpolates_between_annotations() {
        let eth = Recording::load(&dataset("ETH/seq_eth")).expect("seq_eth loads");
        let track = eth.track(1).expect("pedestrian 1");
        let (a, b) = (track.samples[0], track.samples[1]);
        let (p, v) = track.state_at(0.1).expect("inside");
        assert!((p - (a.position + (b.position - a.position) * 0.25)).norm() < 1e-12);
        assert!((v - (a.velocity + (b.velocity - a.velocity) * 0.25)).norm() < 1e-12);
        assert_eq!(track.state_at(0.4).map(|s| s.0), Some(b.position));
        assert!(track.state_at(-0.1).is_none());
        assert!(track.state_at(track.end() + 0.1).is_none());
        assert!(eth.people_at(0.0, Some(1)).all(|(id, _, _)| id != 1));
    }

    #[test]
    fn malformed_obsmat_lines_are_named() {
        let err = |text: &str| parse_obsmat(text, 0.4).expect_err("malformed");
        let e = err("1 1 0 0 0 0 0 0\n2 1 0 0 0 0\n");
        assert_eq!(e.line, 2);
        assert!(e.message.contains("expected 8 columns"), "{}", e.message);
        let e = err("1 1 0 0 abc 0 0 0\n");
        assert!(
            e.message.contains("column 5") && e.message.contains("abc"),
            "{}",
            e.message
        );
        let e = err("1 1 0 0 nan 0 0 0\n");
        assert!(e.message.contains("not finite"), "{}", e.message);
        let e = err("1.5 1 0 0 0 0 0 0\n");
        assert!(e.message.contains("frame number"), "{}", e.message);
        let e = err("1 -2 0 0 0 0 0 0\n");
        assert!(e.message.contains("pedestrian id"), "{}", e.message);
        let e = err("1 1 0 0 0 0 0 0\n1 1 1 0 1 0 0 0\n");
        assert_eq!(e.line, 2);
        assert!(e.message.contains("twice in frame 1"), "{}", e.message);
        let e = err("\n  \n");
        assert_eq!((e.line, e.message.as_str()), (0, "no observations"));
    }

    #[test]
    fn malformed_files_are_reported_with_their_path() {
        let tmp = tempfile::tempdir().expect("a temporary folder");
        let dir = tmp.path().join("dataset");
        std::fs::create_dir_all(&dir).expect("temp dir");
        let missing = Recording::load(&dir).expect_err("no obsmat.txt");
        assert!(missing.to_string().contains("obsmat.txt"), "{missing}");
        std::fs::write(dir.join("obsmat.txt"), "1 1 0 0 0 0 0 0\n2 x\n").expect("write");
        let bad = Recording::load(&dir).expect_err("bad line");
        assert!(bad.to_string().contains("obsmat.txt:2:"), "{bad}");
        std::fs::write(dir.join("obsmat.txt"), "1 1 0 0 0 0 0 0\n").expect("write");
        std::fs::write(
            dir.join("map.xml"),
            "<Trial><Line x1=\"0\" y1=\"zero\" x2=\"1\" y2=\"1\"/></Trial>",
        )
        .expect("write");
        let bad = Recording::load(&dir).expect_err("bad map");
        assert!(bad.to_string().contains("y1=\"zero\""), "{bad}");
        std::fs::write(dir.join("map.xml"), "<Trial><Line").expect("write");
        let bad = Recording::load(&dir).expect_err("bad xml");
        assert!(bad.to_string().contains("not valid XML"), "{bad}");
        std::fs::remove_file(dir.join("map.xml")).expect("remove");
        let ok = Recording::load(&dir).expect("map.xml is optional");
        assert!(ok.walls.is_empty());
        // Without destinations.txt the one track's end is the one destination.
        assert_eq!(ok.destinations, vec![Vec2::new(0.0, 0.0)]);
        assert!(!ok.destinations_from_file);
        std::fs::write(dir.join("destinations.txt"), "1 2\n3 four\n").expect("write");
        let bad = Recording::load(&dir).expect_err("bad destination");
        assert!(bad.to_string().contains("destinations.txt:2:"), "{bad}");
        // One standing person: no steps, so no file can fit; the end point is used.
        std::fs::write(dir.join("destinations.txt"), "1 2\n\n3 4\n").expect("write");
        let listed = Recording::load(&dir).expect("destinations listed");
        assert_eq!(listed.destinations, vec![Vec2::new(0.0, 0.0)]);
        assert_eq!(listed.rejected_destinations_fit, Some(0.0));
        // Someone walking +x to (4, 0): a file with (5, 0) fits, one with (0, 5) does not.
        std::fs::write(
            dir.join("obsmat.txt"),
            "1 1 0 0 0 0 0 0\n2 1 1 0 0 0 0 0\n3 1 2 0 0 0 0 0\n4 1 4 0 0 0 0 0\n",
        )
        .expect("write");
        std::fs::write(dir.join("destinations.txt"), "5 0\n0 5\n").expect("write");
        let fits = Recording::load(&dir).expect("fits");
        assert!(fits.destinations_from_file && fits.destinations_fit == 1.0);
        std::fs::write(dir.join("destinations.txt"), "0 5\n").expect("write");
        let off = Recording::load(&dir).expect("set aside");
        assert!(!off.destinations_from_file);
        assert_eq!(off.destinations, vec![Vec2::new(4.0, 0.0)]);
    }

    #[test]
    fn end_points_cluster_into_destinations() {
        // Ten tracks ending near (0, 10) and ten near (10, 0), spread ±0.5 m.
        let tracks: Vec<Track> = (0..20)
            .map(|i| {
                let off = (i % 5) as Real * 0.25 - 0.5;
                let end = if i < 10 {
                    Vec2::new(off, 10.0)
                } else {
                    Vec2::new(10.0, off)
                };
                Track {
                    id: i,
                    samples: vec![Sample {
                        t: 0.0,
                        position: end,
                        velocity: Vec2::zeros(),
                    }],
                }
            })
            .collect();
        let mut centres = cluster_destinations(&tracks, 2);
        centres.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(centres.len(), 2);
        assert!(
            (centres[0] - Vec2::new(0.0, 10.0)).norm() < 1e-9,
            "{centres:?}"
        );
        assert!(
            (centres[1] - Vec2::new(10.0, 0.0)).norm() < 1e-9,
            "{centres:?}"
        );
        // seq_eth's file fits its tracks (ETH's four exits); zara01's is in another frame and
        // is set aside for its end points clustered.
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets");
        let eth = Recording::load(&data.join("ETH/seq_eth")).expect("seq_eth");
        assert!(eth.destinations_from_file && eth.destinations.len() == 4);
        assert!(eth.destinations_fit > 0.9, "{}", eth.destinations_fit);
        let zara = Recording::load(&data.join("UCY/zara01")).expect("zara01");
        assert!(!zara.destinations_from_file && zara.destinations.len() == 4);
        let rejected = zara.rejected_destinations_fit.expect("file set aside");
        assert!(
            rejected < 0.45 && zara.destinations_fit > 0.9,
            "{rejected} {}",
            zara.destinations_fit
        );
    }

    #[test]
    fn the_frame_step_is_inferred_per_file() {
        // Annotated every 10 frames with one gap of 20: still 0.4 s per 10 frames.
        let text = "100 1 0 0 0 0 0 0\n110 1 1 0 0 0 0 0\n130 1 2 0 0 0 0 0\n110 2 5 0 5 0 0 0\n";
        let tracks = parse_obsmat(text, 0.4).expect("valid");
        let times: Vec<Real> = tracks[0].samples.iter().map(|s| s.t).collect();
        assert!(
            times
                .iter()
                .zip([0.0, 0.4, 1.2])
                .all(|(t, e)| (t - e).abs() < 1e-12),
            "{times:?}"
        );
        assert_eq!(tracks[1].samples[0].t, 0.4);
    }
}
