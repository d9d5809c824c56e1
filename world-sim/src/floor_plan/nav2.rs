//! Nav2 map files: a `map.yaml` naming an image, read as nav2_map_server's `map_io` reads them
//! in trinary mode, into an occupancy grid.
//!
//! For each pixel, `shade` is the mean of its colour channels (and, when the image has an
//! alpha channel, of its alpha too, as `map_io` does in trinary mode) on a scale of 0 to 1;
//! `occ` is `1 − shade`, or `shade` with `negate`. A cell is occupied when
//! `occupied_thresh < occ`, free when `occ < free_thresh`, unknown otherwise. The image's top
//! row is the grid's last: row 0 of the grid is the bottom of the image, and `origin` is the
//! lower-left corner of the lower-left cell, in metres, in the map frame.
//!
//! Images are PNG (any colour type and depth; 16-bit channels are read at 8 bits) or binary
//! and plain PGM (P5, P2). Everything is checked before use: sizes against [`MAX_PIXELS`],
//! numbers for range, the image's path for staying inside the YAML's folder. Every error
//! names the field or file at fault.

use agent::math::{Real, Vec2, vec2};
use std::path::{Component, Path, PathBuf};

/// Most pixels an image may have (64 M: 8,000 × 8,000).
pub const MAX_PIXELS: usize = 64 << 20;
/// Most pixels along either side.
pub const MAX_SIDE: usize = 32_768;
/// Largest map file (YAML or image) read, bytes.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// A cell's state, as in `nav_msgs/OccupancyGrid` (0 free, 100 occupied, −1 unknown).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cell {
    /// Nothing there.
    Free,
    /// A wall, shelf or anything else solid.
    Occupied,
    /// Not mapped.
    Unknown,
}

impl Cell {
    /// The value `nav_msgs/OccupancyGrid` carries for it.
    pub fn occupancy(self) -> i8 {
        match self {
            Self::Free => 0,
            Self::Occupied => 100,
            Self::Unknown => -1,
        }
    }
}

/// A map as nav2_map_server serves it.
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    /// Cells along x.
    pub width: usize,
    /// Cells along y.
    pub height: usize,
    /// Side of a cell (m).
    pub resolution: Real,
    /// The lower-left corner of cell (0, 0) in the map frame (m).
    pub origin: Vec2,
    /// Row-major from the bottom row: cell (x, y) is `cells[y * width + x]`.
    pub cells: Vec<Cell>,
}

impl OccupancyGrid {
    /// Cell (x, y).
    pub fn at(&self, x: usize, y: usize) -> Cell {
        self.cells[y * self.width + x]
    }

    /// The cell holding map-frame point `p`, if the grid covers it.
    pub fn cell_of(&self, p: Vec2) -> Option<(usize, usize)> {
        let x = ((p.x - self.origin.x) / self.resolution).floor();
        let y = ((p.y - self.origin.y) / self.resolution).floor();
        (x >= 0.0 && y >= 0.0 && (x as usize) < self.width && (y as usize) < self.height)
            .then_some((x as usize, y as usize))
    }

    /// The centre of cell (x, y) in the map frame.
    pub fn centre(&self, x: usize, y: usize) -> Vec2 {
        self.origin + vec2(x as Real + 0.5, y as Real + 0.5) * self.resolution
    }

    /// The upper-right corner of the grid in the map frame.
    pub fn far_corner(&self) -> Vec2 {
        self.origin + vec2(self.width as Real, self.height as Real) * self.resolution
    }
}

/// Why a map could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapFileError {
    /// A file could not be read.
    #[error("map {file}: {reason}")]
    Read {
        /// The file.
        file: String,
        /// The system's message.
        reason: String,
    },
    /// A YAML field missing, of the wrong type or out of range.
    #[error("map {file}: field `{field}` {reason}")]
    Field {
        /// The YAML file.
        file: String,
        /// The field.
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The image is not one this loader reads, or is damaged or too large.
    #[error("map image {file}: {reason}")]
    Image {
        /// The image file.
        file: String,
        /// What is wrong with it.
        reason: String,
    },
}

/// The YAML's fields, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct MapYaml {
    /// The image's path as written (relative to the YAML's folder).
    pub image: String,
    /// Metres per pixel.
    pub resolution: Real,
    /// x, y of the lower-left corner and the yaw (which must be 0).
    pub origin: [Real; 3],
    /// Whether dark means free.
    pub negate: bool,
    /// Above this occupancy a cell is occupied.
    pub occupied_thresh: Real,
    /// Below this a cell is free.
    pub free_thresh: Real,
}

impl MapYaml {
    /// Parses a map.yaml's text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self, MapFileError> {
        let field = |field: &'static str, reason: String| MapFileError::Field {
            file: file.to_owned(),
            field,
            reason,
        };
        let doc: serde_yaml::Value = serde_yaml::from_str(text)
            .map_err(|e| field("(document)", format!("is not YAML: {e}")))?;
        let get = |name: &'static str| {
            doc.get(name)
                .ok_or_else(|| field(name, "is missing".to_owned()))
        };
        let number = |name: &'static str| -> Result<Real, MapFileError> {
            let v = get(name)?
                .as_f64()
                .ok_or_else(|| field(name, "is not a number".to_owned()))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(field(name, format!("is {v}, not a finite number")))
            }
        };
        let image = get("image")?
            .as_str()
            .ok_or_else(|| field("image", "is not a string".to_owned()))?
            .to_owned();
        if image.is_empty() {
            return Err(field("image", "is empty".to_owned()));
        }
        let resolution = number("resolution")?;
        if !(0.001..=10.0).contains(&resolution) {
            return Err(field(
                "resolution",
                format!("is {resolution} m per pixel; it must be in [0.001, 10]"),
            ));
        }
        let origin = get("origin")?
            .as_sequence()
            .ok_or_else(|| field("origin", "is not a list [x, y, yaw]".to_owned()))?;
        if origin.len() != 3 {
            return Err(field(
                "origin",
                format!("has {} elements, not 3 (x, y, yaw)", origin.len()),
            ));
        }
        let mut xyz = [0.0; 3];
        for (v, o) in xyz.iter_mut().zip(origin) {
            *v = o
                .as_f64()
                .filter(|v| v.is_finite() && v.abs() <= 1e6)
                .ok_or_else(|| field("origin", format!("{o:?} is not a number within 1e6")))?;
        }
        if xyz[2] != 0.0 {
            return Err(field(
                "origin",
                format!(
                    "has a yaw of {} rad; only maps with yaw 0 are supported (rotate the image)",
                    xyz[2]
                ),
            ));
        }
        // yaml-cpp reads negate as an int, or failing that a bool; map_io does the same.
        let negate = match get("negate")? {
            serde_yaml::Value::Number(n) => n.as_i64().map(|n| n != 0),
            serde_yaml::Value::Bool(b) => Some(*b),
            _ => None,
        }
        .ok_or_else(|| field("negate", "is neither 0/1 nor true/false".to_owned()))?;
        let occupied_thresh = number("occupied_thresh")?;
        let free_thresh = number("free_thresh")?;
        if !(0.0..=1.0).contains(&occupied_thresh) {
            return Err(field(
                "occupied_thresh",
                format!("is {occupied_thresh}; it must be in [0, 1]"),
            ));
        }
        if !(0.0..occupied_thresh).contains(&free_thresh) {
            return Err(field(
                "free_thresh",
                format!("is {free_thresh}; it must be in [0, occupied_thresh)"),
            ));
        }
        if let Some(mode) = doc.get("mode")
            && mode.as_str() != Some("trinary")
        {
            return Err(field(
                "mode",
                format!("is {mode:?}; only \"trinary\" (Nav2's default) is supported"),
            ));
        }
        Ok(Self {
            image,
            resolution,
            origin: xyz,
            negate,
            occupied_thresh,
            free_thresh,
        })
    }

    /// The image's path: `image` taken relative to `folder`, refused when it is absolute or
    /// climbs out of the folder (`..`).
    pub fn image_path(&self, folder: &Path, file: &str) -> Result<PathBuf, MapFileError> {
        let relative = Path::new(&self.image);
        let inside = relative
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
        if !inside {
            return Err(MapFileError::Field {
                file: file.to_owned(),
                field: "image",
                reason: format!(
                    "{:?} is outside the YAML's folder; name a file in it or below",
                    self.image
                ),
            });
        }
        Ok(folder.join(relative))
    }

    /// The grid of `image`'s pixels (the image's bytes; `file` names it in errors).
    pub fn grid(&self, image: &[u8], file: &str) -> Result<OccupancyGrid, MapFileError> {
        let pixels = decode(image).map_err(|reason| MapFileError::Image {
            file: file.to_owned(),
            reason,
        })?;
        let (w, h) = (pixels.width, pixels.height);
        let extent = w.max(h) as Real * self.resolution;
        if extent > 100_000.0 {
            return Err(MapFileError::Field {
                file: file.to_owned(),
                field: "resolution",
                reason: format!("makes the map {extent:.0} m across; at most 100 km is supported"),
            });
        }
        let mut cells = vec![Cell::Unknown; w * h];
        for row in 0..h {
            for x in 0..w {
                let shade = pixels.shade(x, row);
                let occ = if self.negate { shade } else { 1.0 - shade };
                let cell = if self.occupied_thresh < occ {
                    Cell::Occupied
                } else if occ < self.free_thresh {
                    Cell::Free
                } else {
                    Cell::Unknown
                };
                cells[(h - 1 - row) * w + x] = cell;
            }
        }
        Ok(OccupancyGrid {
            width: w,
            height: h,
            resolution: self.resolution,
            origin: vec2(self.origin[0], self.origin[1]),
            cells,
        })
    }
}

/// A map read from disk: its grid and the FNV-1a fingerprint of the YAML and image bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct Loaded {
    /// The YAML's fields.
    pub meta: MapYaml,
    /// The cells.
    pub grid: OccupancyGrid,
    /// [`fingerprint`] of the bytes read.
    pub fingerprint: u64,
}

/// FNV-1a over a map's YAML text and image bytes: two runs on the same fingerprint ran on the
/// same map.
pub fn fingerprint(yaml: &[u8], image: &[u8]) -> u64 {
    yaml.iter()
        .chain(image)
        .fold(0xcbf2_9ce4_8422_2325, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
}

/// Reads a map.yaml and its image from disk.
pub fn load(yaml: &Path) -> Result<Loaded, MapFileError> {
    let file = yaml.display().to_string();
    let yaml_bytes = read(yaml)?;
    let text = std::str::from_utf8(&yaml_bytes).map_err(|_| MapFileError::Read {
        file: file.clone(),
        reason: "is not UTF-8 text".to_owned(),
    })?;
    let meta = MapYaml::parse(text, &file)?;
    let folder = yaml.parent().unwrap_or(Path::new("."));
    let image = meta.image_path(folder, &file)?;
    // A symbolic link may still lead out of the folder: compare the resolved paths.
    let (real_folder, real_image) = (folder.canonicalize(), image.canonicalize());
    if let (Ok(f), Ok(i)) = (&real_folder, &real_image)
        && !i.starts_with(f)
    {
        return Err(MapFileError::Field {
            file,
            field: "image",
            reason: format!("{:?} leads outside the YAML's folder", meta.image),
        });
    }
    let bytes = read(&image)?;
    let grid = meta.grid(&bytes, &image.display().to_string())?;
    Ok(Loaded {
        fingerprint: fingerprint(&yaml_bytes, &bytes),
        meta,
        grid,
    })
}

fn read(path: &Path) -> Result<Vec<u8>, MapFileError> {
    let error = |reason: String| MapFileError::Read {
        file: path.display().to_string(),
        reason,
    };
    let size = std::fs::metadata(path)
        .map_err(|e| error(e.to_string()))?
        .len();
    if size > MAX_FILE_BYTES {
        return Err(error(format!(
            "is {size} bytes; at most {MAX_FILE_BYTES} are read"
        )));
    }
    std::fs::read(path).map_err(|e| error(e.to_string()))
}

/// Decoded pixels: `channels` 8-bit samples per pixel, rows top to bottom.
struct Pixels {
    width: usize,
    height: usize,
    /// Colour channels (1 grey or 3 RGB), then alpha if `alpha`.
    colours: usize,
    alpha: bool,
    samples: Vec<u8>,
}

impl Pixels {
    /// map_io's shade of pixel (x, row): the mean of R, G, B (grey counts three times) and,
    /// with alpha, the alpha, over 255.
    fn shade(&self, x: usize, row: usize) -> Real {
        let stride = self.colours + usize::from(self.alpha);
        let at = (row * self.width + x) * stride;
        let px = &self.samples[at..at + stride];
        let (sum, n) = match self.colours {
            1 => (3 * u32::from(px[0]), 3),
            _ => (px[..3].iter().map(|&c| u32::from(c)).sum(), 3),
        };
        let (sum, n) = if self.alpha {
            (sum + u32::from(px[self.colours]), n + 1)
        } else {
            (sum, n)
        };
        Real::from(sum) / Real::from(n) / 255.0
    }
}

fn check_size(width: usize, height: usize) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("is {width} × {height} pixels: empty"));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width * height > MAX_PIXELS {
        return Err(format!(
            "is {width} × {height} pixels; at most {MAX_SIDE} a side and {MAX_PIXELS} in all"
        ));
    }
    Ok(())
}

fn decode(bytes: &[u8]) -> Result<Pixels, String> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        decode_png(bytes)
    } else if bytes.starts_with(b"P5") || bytes.starts_with(b"P2") {
        decode_pgm(bytes)
    } else {
        Err("is neither a PNG nor a PGM (P5 or P2) image".to_owned())
    }
}

fn decode_png(bytes: &[u8]) -> Result<Pixels, String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    // Palettes and low depths to 8 bits, transparency chunks to alpha, 16 bits to 8.
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    decoder.set_limits(png::Limits {
        bytes: MAX_PIXELS * 4,
    });
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("is not a readable PNG: {e}"))?;
    let info = reader.info();
    check_size(info.width as usize, info.height as usize)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| "is too large to decode".to_owned())?;
    let mut samples = vec![0; size];
    let frame = reader
        .next_frame(&mut samples)
        .map_err(|e| format!("is a damaged PNG: {e}"))?;
    let (colours, alpha) = match frame.color_type {
        png::ColorType::Grayscale => (1, false),
        png::ColorType::GrayscaleAlpha => (1, true),
        png::ColorType::Rgb => (3, false),
        png::ColorType::Rgba => (3, true),
        png::ColorType::Indexed => return Err("kept its palette after expansion".to_owned()),
    };
    if frame.bit_depth != png::BitDepth::Eight {
        return Err(format!(
            "has {:?}-bit samples after expansion",
            frame.bit_depth
        ));
    }
    let (width, height) = (frame.width as usize, frame.height as usize);
    let stride = colours + usize::from(alpha);
    let row_bytes = width * stride;
    // Rows may be padded to `frame.line_size`; keep them packed.
    let packed = if frame.line_size == row_bytes {
        samples.truncate(row_bytes * height);
        samples
    } else {
        (0..height)
            .flat_map(|r| samples[r * frame.line_size..r * frame.line_size + row_bytes].to_vec())
            .collect()
    };
    Ok(Pixels {
        width,
        height,
        colours,
        alpha,
        samples: packed,
    })
}

/// Netpbm's greymap: "P5" (binary) or "P2" (plain), width, height, maxval, separated by
/// whitespace and `#` comments; samples of 1 byte (maxval < 256) or 2 (big-endian).
fn decode_pgm(bytes: &[u8]) -> Result<Pixels, String> {
    let binary = bytes.starts_with(b"P5");
    let mut at = 2;
    let mut header = [0usize; 3];
    for value in &mut header {
        loop {
            match bytes.get(at) {
                Some(b'#') => {
                    while bytes.get(at).is_some_and(|&b| b != b'\n') {
                        at += 1;
                    }
                }
                Some(b) if b.is_ascii_whitespace() => at += 1,
                _ => break,
            }
        }
        let start = at;
        while bytes.get(at).is_some_and(u8::is_ascii_digit) {
            at += 1;
        }
        *value = std::str::from_utf8(&bytes[start..at])
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| "has a damaged PGM header".to_owned())?;
    }
    let [width, height, maxval] = header;
    check_size(width, height)?;
    if !(1..=65535).contains(&maxval) {
        return Err(format!("has maxval {maxval}; PGM allows 1 to 65535"));
    }
    // One whitespace byte ends the header.
    if !bytes.get(at).is_some_and(u8::is_ascii_whitespace) {
        return Err("has a damaged PGM header".to_owned());
    }
    at += 1;
    let n = width * height;
    let raw: Vec<u32> = if binary {
        let wide = maxval > 255;
        let need = n * if wide { 2 } else { 1 };
        let data = bytes
            .get(at..at + need)
            .ok_or_else(|| format!("ends early: {} of {need} sample bytes", bytes.len() - at))?;
        if wide {
            data.chunks_exact(2)
                .map(|c| u32::from(u16::from_be_bytes([c[0], c[1]])))
                .collect()
        } else {
            data.iter().map(|&b| u32::from(b)).collect()
        }
    } else {
        let text = std::str::from_utf8(&bytes[at..]).map_err(|_| "has non-text samples")?;
        let values: Vec<u32> = text
            .split_ascii_whitespace()
            .take(n)
            .map(|s| s.parse().map_err(|_| format!("has a bad sample {s:?}")))
            .collect::<Result<_, _>>()?;
        if values.len() < n {
            return Err(format!("ends early: {} of {n} samples", values.len()));
        }
        values
    };
    let maxval = maxval as u32;
    let samples = raw
        .into_iter()
        .map(|v| {
            if v > maxval {
                Err(format!("has a sample {v} above its maxval {maxval}"))
            } else {
                // To 8 bits, rounding, as a Q8 image library would hold it.
                Ok(((v * 255 + maxval / 2) / maxval) as u8)
            }
        })
        .collect::<Result<_, _>>()?;
    Ok(Pixels {
        width,
        height,
        colours: 1,
        alpha: false,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const YAML: &str = "image: m.pgm\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";

    #[test]
    fn pgm_rows_run_bottom_up_and_thresholds_split_three_ways() {
        // Top row: black, white; bottom row: grey, white.
        let pgm = b"P5\n# a comment\n2 2\n255\n\x00\xff\x80\xff";
        let meta = MapYaml::parse(YAML, "m.yaml").expect("valid");
        let grid = meta.grid(pgm, "m.pgm").expect("decodes");
        assert_eq!((grid.width, grid.height), (2, 2));
        assert_eq!(grid.at(0, 1), Cell::Occupied);
        assert_eq!(grid.at(1, 1), Cell::Free);
        assert_eq!(grid.at(0, 0), Cell::Unknown);
        assert_eq!(grid.at(1, 0), Cell::Free);
        assert_eq!(grid.centre(0, 0), vec2(-0.75, 2.25));
        assert_eq!(grid.cell_of(vec2(-0.1, 2.9)), Some((1, 1)));
        assert_eq!(grid.cell_of(vec2(-1.1, 2.9)), None);
        let plain = b"P2 2 2 255\n0 255\n128 255\n";
        assert_eq!(meta.grid(plain, "m.pgm").expect("decodes"), grid);
    }

    #[test]
    fn negate_swaps_black_and_white() {
        let meta =
            MapYaml::parse(&YAML.replace("negate: 0", "negate: true"), "m.yaml").expect("valid");
        let grid = meta.grid(b"P5 1 1 255\n\x00", "m.pgm").expect("decodes");
        assert_eq!(grid.at(0, 0), Cell::Free);
    }

    #[test]
    fn bad_fields_are_named() {
        let cases = [
            ("resolution: 0.5", "resolution: 0", "resolution"),
            ("resolution: 0.5", "resolution: 1e9", "resolution"),
            ("resolution: 0.5", "resolution: .nan", "resolution"),
            ("origin: [-1.0, 2.0, 0.0]", "origin: [1, 2]", "origin"),
            ("origin: [-1.0, 2.0, 0.0]", "origin: [1, 2, 0.5]", "origin"),
            ("image: m.pgm", "image: ../m.pgm", "image"),
            ("image: m.pgm", "image: /etc/passwd", "image"),
            ("free_thresh: 0.196", "free_thresh: 0.9", "free_thresh"),
            ("negate: 0", "negate: maybe", "negate"),
            ("image: m.pgm\n", "", "image"),
        ];
        for (from, to, field) in cases {
            let text = YAML.replace(from, to);
            let result = MapYaml::parse(&text, "m.yaml")
                .and_then(|m| m.image_path(Path::new("/maps"), "m.yaml").map(|_| m));
            match result {
                Err(MapFileError::Field { field: f, .. }) => assert_eq!(f, field, "{to}"),
                other => panic!("{to}: {other:?}"),
            }
        }
        let mode = MapYaml::parse(&format!("{YAML}mode: scale\n"), "m.yaml");
        assert!(matches!(
            mode,
            Err(MapFileError::Field { field: "mode", .. })
        ));
    }

    #[test]
    fn bad_images_are_refused_with_a_reason() {
        let meta = MapYaml::parse(YAML, "m.yaml").expect("valid");
        for (bytes, what) in [
            (&b"GIF89a..."[..], "neither a PNG nor a PGM"),
            (b"P5 2 2 255\n\x00", "ends early"),
            (b"P5 0 2 255\n", "empty"),
            (b"P5 99999 99999 255\n", "at most"),
            (b"P2 1 1 10\n11\n", "above its maxval"),
            (b"\x89PNG\r\n\x1a\nnot really", "not a readable PNG"),
        ] {
            match meta.grid(bytes, "m") {
                Err(MapFileError::Image { reason, .. }) => {
                    assert!(reason.contains(what), "{reason}")
                }
                other => panic!("{what}: {other:?}"),
            }
        }
    }

    #[test]
    fn png_alpha_counts_as_map_io_averages_it() {
        // Grey 200 with alpha 0: shade (3·200 + 0)/4/255 = 0.588, occ 0.41: unknown. The same
        // grey opaque: shade (3·200 + 255)/4/255 = 0.838, occ 0.162: free (without the alpha
        // it would be occ 0.216: unknown). White, opaque: free.
        let mut png_bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut png_bytes, 3, 1);
            enc.set_color(png::ColorType::GrayscaleAlpha);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().expect("header");
            w.write_image_data(&[200, 0, 200, 255, 255, 255])
                .expect("data");
        }
        let meta = MapYaml::parse(YAML, "m.yaml").expect("valid");
        let grid = meta.grid(&png_bytes, "m.png").expect("decodes");
        assert_eq!(grid.cells, vec![Cell::Unknown, Cell::Free, Cell::Free]);
    }
}
