//! C3D: the binary motion-capture interchange format (<https://www.c3d.org>), read. (The
//! writer for our own exports is in the `io` layer: `io::c3d_write`.)
//!
//! # Layout, as read here
//!
//! The file is a sequence of 512-byte blocks.
//!
//! * **Header** (block 1), 16-bit words: byte 1 the parameter section's first block,
//!   byte 2 the key `0x50`; word 2 the number of 3D points; word 3 the analog values per
//!   frame (channels × samples); words 4 and 5 the first and last frame numbers; words
//!   7–8 the scale factor (a float: negative means the point data are floats); word 9
//!   the first block of the data; word 10 the analog samples per frame; words 11–12 the
//!   frame rate (a float).
//! * **Parameter section**: 4 bytes (the 4th is the processor type: 84 Intel, 85 DEC,
//!   86 MIPS, which fixes the byte order and float format of every number in the file,
//!   header included), then records: a signed name length (negative = locked), an id
//!   (negative: a group; positive: a parameter of the group with the opposite id), the
//!   name, a 16-bit offset from itself to the next record (0: last), then for a
//!   parameter its data type (−1 char, 1 byte, 2 int16, 4 float), its dimensions and its
//!   data, then a description.
//! * **Data**: for each frame, for each point X, Y, Z and a residual word (int16 times
//!   |scale|, or float32), then the frame's analog values (int16 or float32), which are
//!   skipped here. A negative residual marks the point invalid (not seen): it is read as
//!   `None`. A point whose residual says valid but whose float coordinates are NaN or
//!   ±infinity (some exporters mark an unseen marker so) is `None` too, counted in the
//!   take's gap note with those at exactly (0, 0, 0).
//!
//! Parameters used: `POINT:USED`, `RATE`, `SCALE`, `UNITS` (default mm), `LABELS`
//! (`LABELS2`, `LABELS3`, … for more than 255 points; a missing or blank label becomes
//! `point_<n>`), `DATA_START`, `FRAMES`, `LONG_FRAMES`; `TRIAL:ACTUAL_START_FIELD` /
//! `ACTUAL_END_FIELD` (for more than 65535 frames); `ANALOG:USED` and `ANALOG:RATE`.
//!
//! # Quirks handled
//!
//! * DEC floats (VAX F-floating) have their two 16-bit words swapped relative to IEEE
//!   little-endian and an exponent bias 2 larger: the value is the word-swapped IEEE
//!   value divided by 4.
//! * The parameter section's first two bytes are often 0 (Qualisys, Optotrak): ignored.
//! * **Header word 9 and `POINT:DATA_START` disagreeing** on where the data start: the
//!   parameter is taken when it points after the parameters inside the file, with a note
//!   naming both blocks (`layout`).
//! * The frame count is the header's last − first + 1; `POINT:FRAMES` (an int16 that may
//!   be meant unsigned) and `POINT:LONG_FRAMES` / `TRIAL` fields are used when they show
//!   the header overflowed; without those, a last frame clamped at 65535 or a count
//!   short of the data by whole turns of 65536 gives way to the data's whole frames,
//!   with a note (`layout`).
//! * **A data section that stops early** (fewer whole frames in the file than declared)
//!   is read up to the last whole frame; the take keeps the declared length with the
//!   frames that are not in the file marked missing, and says so in its notes ([`inspect`]
//!   reports both counts). A file with no whole frame at all is refused. (The Optotrak sample shipped with
//!   ezc3d declares 1149 frames but holds 29.)

mod layout;

use super::LengthUnit;
use crate::mocap::take::{ImportError, MarkedGaps, Take, Track};
use glam::DVec3;
use std::path::Path;

/// Bytes per C3D block.
pub(crate) const BLOCK: usize = 512;
/// The key in the header's second byte.
pub(crate) const KEY: u8 = 0x50;

/// The processor (number format) a C3D file was written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Processor {
    /// Little-endian integers, IEEE floats (processor type 84).
    Intel,
    /// Little-endian integers, VAX F-floating floats (85).
    Dec,
    /// Big-endian integers and IEEE floats (86).
    Mips,
}

impl Processor {
    fn from_byte(b: u8) -> Option<Processor> {
        match b {
            84 => Some(Processor::Intel),
            85 => Some(Processor::Dec),
            86 => Some(Processor::Mips),
            _ => None,
        }
    }

    fn i16(self, b: [u8; 2]) -> i16 {
        match self {
            Processor::Mips => i16::from_be_bytes(b),
            _ => i16::from_le_bytes(b),
        }
    }

    fn f32(self, b: [u8; 4]) -> f32 {
        match self {
            Processor::Intel => f32::from_le_bytes(b),
            Processor::Mips => f32::from_be_bytes(b),
            Processor::Dec => dec_to_f32(b),
        }
    }
}

/// A VAX F-floating value as stored in a DEC C3D file. Its 16-bit words are swapped
/// relative to an IEEE little-endian float; the fraction has the same bits, but the
/// hidden bit stands for 0.5 rather than 1 and the exponent bias is 128, so the value is
/// the word-swapped IEEE value / 4. Exponent 0 is zero (with the sign set, a "reserved
/// operand", returned as −0 so a residual reads as invalid).
pub(crate) fn dec_to_f32(b: [u8; 4]) -> f32 {
    let bits = u32::from_le_bytes([b[2], b[3], b[0], b[1]]);
    let negative = bits >> 31 == 1;
    let exp = ((bits >> 23) & 0xff) as i32;
    if exp == 0 {
        return if negative { -0.0 } else { 0.0 };
    }
    let mantissa = 1.0 + f64::from(bits & 0x7f_ffff) / f64::from(1u32 << 23);
    let v = mantissa * 2f64.powi(exp - 129);
    (if negative { -v } else { v }) as f32
}

/// Bounds-checked reads of a C3D file's numbers, with errors naming the byte offset.
struct Bin<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    proc: Processor,
}

impl<'a> Bin<'a> {
    fn slice(&self, off: usize, len: usize, what: &str) -> Result<&'a [u8], ImportError> {
        off.checked_add(len)
            .and_then(|end| self.bytes.get(off..end))
            .ok_or_else(|| {
                ImportError::format(
                    self.path,
                    format!("byte {off}"),
                    format!(
                        "expected {len} bytes of {what}, found the end of the file (it is {} \
                         bytes long: truncated?)",
                        self.bytes.len()
                    ),
                )
            })
    }

    fn array<const N: usize>(&self, off: usize, what: &str) -> Result<[u8; N], ImportError> {
        let s = self.slice(off, N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    fn u8(&self, off: usize, what: &str) -> Result<u8, ImportError> {
        Ok(self.array::<1>(off, what)?[0])
    }

    fn i16(&self, off: usize, what: &str) -> Result<i16, ImportError> {
        Ok(self.proc.i16(self.array(off, what)?))
    }

    /// An int16 word meant as unsigned (counts, frame numbers, block numbers).
    fn u16(&self, off: usize, what: &str) -> Result<u16, ImportError> {
        Ok(self.i16(off, what)? as u16)
    }

    fn f32(&self, off: usize, what: &str) -> Result<f32, ImportError> {
        Ok(self.proc.f32(self.array(off, what)?))
    }
}

/// One parameter record.
struct Param<'a> {
    group: String,
    name: String,
    /// −1 char, 1 byte, 2 int16, 4 float.
    kind: i8,
    dims: Vec<usize>,
    data: &'a [u8],
}

/// All parameters of a file.
struct Params<'a> {
    proc: Processor,
    list: Vec<Param<'a>>,
    /// Byte offset just past the last record's name, offset word and data.
    end: usize,
}

impl<'a> Params<'a> {
    fn get(&self, group: &str, name: &str) -> Option<&Param<'a>> {
        self.list
            .iter()
            .find(|p| p.group.eq_ignore_ascii_case(group) && p.name.eq_ignore_ascii_case(name))
    }

    /// All numeric values of a parameter (chars give none).
    fn numbers(&self, p: &Param) -> Vec<f64> {
        let proc = self.proc;
        match p.kind {
            1 => p.data.iter().map(|&b| f64::from(b)).collect(),
            2 => p
                .data
                .chunks_exact(2)
                .map(|c| f64::from(proc.i16([c[0], c[1]])))
                .collect(),
            4 => p
                .data
                .chunks_exact(4)
                .map(|c| f64::from(proc.f32([c[0], c[1], c[2], c[3]])))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// The first value of a numeric parameter, an int16 read as unsigned (counts).
    fn first_count(&self, group: &str, name: &str) -> Option<usize> {
        let p = self.get(group, name)?;
        match p.kind {
            1 => p.data.first().map(|&b| usize::from(b)),
            2 => p
                .data
                .get(..2)
                .map(|c| usize::from(self.proc.i16([c[0], c[1]]) as u16)),
            4 => {
                let v = *self.numbers(p).first()?;
                (0.0..1e12).contains(&v).then(|| v.round() as usize)
            }
            _ => None,
        }
    }

    /// The first value of a numeric parameter.
    fn first_number(&self, group: &str, name: &str) -> Option<f64> {
        self.get(group, name)
            .and_then(|p| self.numbers(p).first().copied())
    }

    /// A 32-bit count stored as two int16 words, low word first (TRIAL fields).
    fn long_field(&self, group: &str, name: &str) -> Option<u32> {
        let p = self.get(group, name)?;
        let n = self.numbers(p);
        match (p.kind, n.as_slice()) {
            (2, [lo, hi, ..]) => {
                Some(u32::from(*lo as i16 as u16) | u32::from(*hi as i16 as u16) << 16)
            }
            _ => None,
        }
    }

    /// The strings of a char parameter: dimensions `[width, count…]` give `count`
    /// strings of `width` bytes; fewer dimensions give one string. Trimmed.
    fn strings(&self, group: &str, name: &str) -> Option<Vec<String>> {
        let p = self.get(group, name)?;
        if p.kind != -1 {
            return None;
        }
        let width = match p.dims.as_slice() {
            [w, _, ..] => *w,
            _ => p.data.len(),
        };
        if width == 0 {
            return Some(Vec::new());
        }
        Some(p.data.chunks(width).map(text).collect())
    }
}

/// Bytes as text (UTF-8 if valid, else Latin-1), trimmed of spaces and NULs.
fn text(b: &[u8]) -> String {
    let s = match std::str::from_utf8(b) {
        Ok(s) => s.to_string(),
        Err(_) => b.iter().map(|&c| char::from(c)).collect(),
    };
    s.trim_matches(|c: char| c.is_whitespace() || c == '\0')
        .to_string()
}

/// What a C3D file declares and holds, before its point data are read.
#[derive(Clone, Debug, PartialEq)]
pub struct C3dInfo {
    /// Number format the file was written in.
    pub processor: Processor,
    /// Number of 3D points per frame.
    pub points: usize,
    /// Point frame rate, Hz.
    pub rate_hz: f64,
    /// The header's first frame number.
    pub first_frame: u32,
    /// Frames the header and parameters declare.
    pub declared_frames: usize,
    /// Whole frames actually present in the data section (≤ declared: what is read).
    pub frames: usize,
    /// True when point data are float32, false when scaled int16.
    pub float_data: bool,
    /// Point scale factor (file units per int16 count; sign as stored).
    pub scale: f64,
    /// `POINT:UNITS` as written ("" when absent).
    pub unit: String,
    /// Analog values per frame (skipped).
    pub analog_values_per_frame: usize,
    /// Byte offset of the first frame.
    pub data_offset: usize,
    /// Point labels, one per point.
    pub labels: Vec<String>,
    /// What the reader had to decide where the header and parameters disagree (data
    /// start, frame count), one sentence each.
    pub notes: Vec<String>,
}

/// Read the header and parameters of a C3D file and work out its layout.
pub fn inspect(path: &Path, bytes: &[u8]) -> Result<C3dInfo, ImportError> {
    Ok(parse(path, bytes)?.0)
}

/// Read a C3D file: one track per 3D point, positions converted to metres from
/// `POINT:UNITS` (or from `unit` when given).
pub fn read(path: &Path, bytes: &[u8], unit: Option<LengthUnit>) -> Result<Take, ImportError> {
    let (info, proc) = parse(path, bytes)?;
    let unit = match unit {
        Some(u) => u,
        None if info.unit.is_empty() => LengthUnit::Millimetre,
        None => LengthUnit::parse(&info.unit).ok_or_else(|| {
            ImportError::format(
                path,
                "parameter POINT:UNITS",
                format!(
                    "expected a length unit \"mm\", \"cm\" or \"m\", found \"{}\" (give a unit \
                     override if the data are in one of these)",
                    info.unit
                ),
            )
        })?,
    };
    let bin = Bin { path, bytes, proc };
    let metres = unit.metres();
    let (point_size, value_size) = value_sizes(info.float_data);
    let frame_size = info.points * point_size + info.analog_values_per_frame * value_size;
    let int_scale = info.scale.abs();
    let mut tracks: Vec<Track> = info
        .labels
        .iter()
        .map(|l| Track {
            label: l.clone(),
            positions: Vec::with_capacity(info.frames),
            rotations: Vec::new(),
        })
        .collect();
    let mut gaps = MarkedGaps::default();
    for f in 0..info.frames {
        let base = info.data_offset + f * frame_size;
        for (p, track) in tracks.iter_mut().enumerate() {
            let o = base + p * point_size;
            let what = "point data";
            let (xyz, invalid) = if info.float_data {
                let xyz = [
                    f64::from(bin.f32(o, what)?),
                    f64::from(bin.f32(o + 4, what)?),
                    f64::from(bin.f32(o + 8, what)?),
                ];
                // The residual slot: a float, or (some writers) two int16 words; either
                // way its sign bit is set when the point is invalid.
                (xyz, bin.f32(o + 12, what)?.is_sign_negative())
            } else {
                let xyz = [
                    f64::from(bin.i16(o, what)?) * int_scale,
                    f64::from(bin.i16(o + 2, what)?) * int_scale,
                    f64::from(bin.i16(o + 4, what)?) * int_scale,
                ];
                (xyz, bin.i16(o + 6, what)? < 0)
            };
            // A point the residual calls valid with a coordinate NaN or infinite: a
            // gap marked the way some exporters mark one, counted.
            let position = if invalid {
                None
            } else if xyz.iter().any(|c| c.is_nan()) {
                gaps.nan += 1;
                None
            } else if xyz.iter().any(|c| c.is_infinite()) {
                gaps.infinite += 1;
                None
            } else {
                Some(DVec3::from_array(xyz) * metres)
            };
            track.positions.push(position);
        }
    }
    let mut notes = info.notes.clone();
    // Keep the declared length (the frames not in the file marked missing) unless the
    // header claims more samples than any real capture holds.
    const MAX_PADDED_SAMPLES: usize = 50_000_000;
    let frames = if info.frames < info.declared_frames {
        let pad = info.declared_frames.saturating_mul(info.points.max(1)) <= MAX_PADDED_SAMPLES;
        let kept = if pad {
            info.declared_frames
        } else {
            info.frames
        };
        notes.push(format!(
            "the data section holds {} of the {} frames the header declares; {}",
            info.frames,
            info.declared_frames,
            if pad {
                "the rest are marked missing"
            } else {
                "only those are read"
            }
        ));
        for t in &mut tracks {
            t.positions.resize(kept, None);
        }
        kept
    } else {
        info.frames
    };
    let mut take = Take {
        source: path.to_path_buf(),
        rate_hz: info.rate_hz,
        frames,
        file_unit: unit.symbol().to_string(),
        tracks,
        notes,
    };
    take.zeros_as_gaps(gaps);
    Ok(take)
}

/// The numbers the header (block 1) holds, in the file's processor format.
struct Header {
    /// Number of 3D points (word 2).
    points: usize,
    /// Analog values per frame, channels × samples (word 3).
    analog_total: usize,
    /// First frame number (word 4).
    first: u16,
    /// Last frame number (word 5).
    last: u16,
    /// Scale factor (words 7–8; negative: the point data are floats).
    scale: f64,
    /// First block of the data (word 9).
    data_block: usize,
    /// Analog samples per frame (word 10).
    analog_samples: usize,
    /// Frame rate, Hz (words 11–12).
    rate: f64,
}

/// Byte offset of the 1-based block `block` (1 or more).
fn block_offset(block: usize) -> usize {
    (block - 1) * BLOCK
}

/// Bytes per point and per analog value in the data section: float32 or int16 words.
fn value_sizes(float_data: bool) -> (usize, usize) {
    if float_data { (16, 4) } else { (8, 2) }
}

/// Header, parameters and layout.
fn parse(path: &Path, bytes: &[u8]) -> Result<(C3dInfo, Processor), ImportError> {
    let (param_block, proc) = processor(path, bytes)?;
    let bin = Bin { path, bytes, proc };
    let h = header(&bin)?;
    let data_hint = (h.data_block > usize::from(param_block)).then(|| block_offset(h.data_block));
    let params = parse_params(&bin, block_offset(usize::from(param_block)) + 4, data_hint)?;

    let points = point_count(path, &params, &h)?;
    let rate_hz = frame_rate(path, &params, &h)?;
    let (float_data, scale) = point_storage(path, &params, &h, points)?;
    let analog_values_per_frame = analog_values_per_frame(path, &params, &h, rate_hz)?;
    let mut notes = Vec::new();
    let data_offset = layout::data_offset(&bin, &params, &h, usize::from(param_block), &mut notes)?;
    let shape = layout::FrameShape {
        points,
        analog: analog_values_per_frame,
        float_data,
    };
    let present = layout::frames_present(
        &bin,
        data_offset,
        &shape,
        &h,
        layout::declared_frames(&params, &h),
        &mut notes,
    )?;
    let labels = point_labels(&params, points);
    let unit = params
        .strings("POINT", "UNITS")
        .and_then(|u| u.into_iter().next())
        .unwrap_or_default();

    Ok((
        C3dInfo {
            processor: proc,
            points,
            rate_hz,
            first_frame: u32::from(h.first),
            declared_frames: present.declared,
            frames: present.frames,
            float_data,
            scale,
            unit,
            analog_values_per_frame,
            data_offset,
            labels,
            notes,
        },
        proc,
    ))
}

/// Check the C3D key and find the parameter section's first block (the header's first byte) and
/// the processor type its 4th byte states, which fixes how every other number is read.
fn processor(path: &Path, bytes: &[u8]) -> Result<(u8, Processor), ImportError> {
    let probe = Bin {
        path,
        bytes,
        proc: Processor::Intel,
    };
    let param_block = probe.u8(0, "the C3D header")?;
    let key = probe.u8(1, "the C3D header")?;
    if key != KEY {
        return Err(ImportError::format(
            path,
            "byte 1",
            format!("expected the C3D key 0x50, found 0x{key:02x}: not a C3D file"),
        ));
    }
    if param_block == 0 {
        return Err(ImportError::format(
            path,
            "byte 0",
            "expected the parameter section's block number (1 or more), found 0",
        ));
    }
    let proc_off = block_offset(usize::from(param_block)) + 3;
    let proc_byte = probe.u8(proc_off, "the parameter section header")?;
    let proc = Processor::from_byte(proc_byte).ok_or_else(|| {
        ImportError::format(
            path,
            format!("byte {proc_off} (processor type)"),
            format!("expected 84 (Intel), 85 (DEC) or 86 (MIPS), found {proc_byte}"),
        )
    })?;
    Ok((param_block, proc))
}

/// Read the header's words.
fn header(bin: &Bin) -> Result<Header, ImportError> {
    let hdr = "the C3D header";
    Ok(Header {
        points: usize::from(bin.u16(2, hdr)?),
        analog_total: usize::from(bin.u16(4, hdr)?),
        first: bin.u16(6, hdr)?,
        last: bin.u16(8, hdr)?,
        scale: f64::from(bin.f32(12, hdr)?),
        data_block: usize::from(bin.u16(16, hdr)?),
        analog_samples: usize::from(bin.u16(18, hdr)?),
        rate: f64::from(bin.f32(20, hdr)?),
    })
}

/// The number of 3D points: the header's, which `POINT:USED` (when present) must match.
fn point_count(path: &Path, params: &Params, h: &Header) -> Result<usize, ImportError> {
    match params.first_count("POINT", "USED") {
        Some(used) if used != h.points => Err(ImportError::format(
            path,
            "parameter POINT:USED",
            format!(
                "expected the header's point count {} (word 2), found {used}: the file is \
                 inconsistent",
                h.points
            ),
        )),
        _ => Ok(h.points),
    }
}

/// The point frame rate, Hz: `POINT:RATE`, else the header's.
fn frame_rate(path: &Path, params: &Params, h: &Header) -> Result<f64, ImportError> {
    match params.first_number("POINT", "RATE") {
        Some(r) if r.is_finite() && r > 0.0 => Ok(r),
        _ if h.rate.is_finite() && h.rate > 0.0 => Ok(h.rate),
        other => Err(ImportError::format(
            path,
            "parameter POINT:RATE",
            format!(
                "expected a frame rate above 0 Hz (here or in header words 11–12), found {}",
                other.unwrap_or(h.rate)
            ),
        )),
    }
}

/// Whether the point data are floats, and the scale factor: the header's sign decides
/// float or int (as most readers do), `POINT:SCALE` gives the factor when it is usable.
fn point_storage(
    path: &Path,
    params: &Params,
    h: &Header,
    points: usize,
) -> Result<(bool, f64), ImportError> {
    let p_scale = params.first_number("POINT", "SCALE");
    let sign_source = if h.scale.is_finite() && h.scale != 0.0 {
        h.scale
    } else {
        p_scale.unwrap_or(h.scale)
    };
    let float_data = sign_source < 0.0;
    let scale = match p_scale {
        Some(s) if s.is_finite() && s != 0.0 => s,
        _ => sign_source,
    };
    if !float_data && points > 0 && !(scale.is_finite() && scale != 0.0) {
        return Err(ImportError::format(
            path,
            "parameter POINT:SCALE",
            format!("expected a non-zero scale factor for integer point data, found {scale}"),
        ));
    }
    Ok((float_data, scale))
}

/// Analog values per frame (skipped, but they set the frame size): `ANALOG:USED`
/// channels times the samples per point frame (header word 10, else `ANALOG:RATE` over
/// the point rate), else the header's total (word 3).
fn analog_values_per_frame(
    path: &Path,
    params: &Params,
    h: &Header,
    rate_hz: f64,
) -> Result<usize, ImportError> {
    let used = match params.first_count("ANALOG", "USED") {
        Some(0) => return Ok(0),
        Some(used) => used,
        None => return Ok(h.analog_total),
    };
    let per = if h.analog_samples > 0 {
        h.analog_samples
    } else {
        match params.first_number("ANALOG", "RATE") {
            Some(ar) if ar.is_finite() && ar > 0.0 => (ar / rate_hz).round() as usize,
            _ => 0,
        }
    };
    if per == 0 {
        return Ok(h.analog_total);
    }
    used.checked_mul(per).ok_or_else(|| {
        ImportError::format(
            path,
            "parameter ANALOG:USED",
            format!("expected a sensible channel count, found {used}"),
        )
    })
}

/// One label per point: `POINT:LABELS`, then `LABELS2`, `LABELS3`, …; a missing or
/// blank label becomes `point_<n>` (1-based).
fn point_labels(params: &Params, points: usize) -> Vec<String> {
    let mut labels: Vec<String> = params.strings("POINT", "LABELS").unwrap_or_default();
    for n in 2.. {
        match params.strings("POINT", &format!("LABELS{n}")) {
            Some(more) => labels.extend(more),
            None => break,
        }
    }
    labels.resize(points, String::new());
    for (i, l) in labels.iter_mut().enumerate() {
        if l.is_empty() {
            *l = format!("point_{}", i + 1);
        }
    }
    labels
}

/// Parse parameter records from `pos` until a zero name length, a zero offset, or
/// (when known) the start of the data.
fn parse_params<'a>(
    bin: &Bin<'a>,
    mut pos: usize,
    data_offset: Option<usize>,
) -> Result<Params<'a>, ImportError> {
    let mut groups: Vec<(u8, String)> = Vec::new();
    // (group id, param) with group names filled in at the end (groups may come later).
    let mut raw: Vec<(u8, Param<'a>)> = Vec::new();
    let what = "a parameter record";
    // The section's own length: byte 2 of its 4-byte header counts its blocks.
    let blocks = usize::from(bin.u8(pos - 2, "the parameter section header")?).max(1);
    let section_end = pos - 4 + blocks * BLOCK;
    let mut end = pos;
    loop {
        if data_offset.is_some_and(|d| pos >= d) {
            break;
        }
        let name_len = bin.u8(pos, what)? as i8;
        if name_len == 0 {
            break;
        }
        let id = bin.u8(pos + 1, what)? as i8;
        let n = usize::from(name_len.unsigned_abs());
        let name = text(bin.slice(pos + 2, n, "a parameter name")?);
        let q = pos + 2 + n;
        let next = bin.u16(q, what)?;
        end = end.max(q + 2);
        if id < 0 {
            groups.push((id.unsigned_abs(), name));
        } else if id > 0 {
            let kind = bin.u8(q + 2, what)? as i8;
            if !matches!(kind, -1 | 1 | 2 | 4) {
                return Err(ImportError::format(
                    bin.path,
                    format!("byte {} (parameter {name})", q + 2),
                    format!("expected a data type −1, 1, 2 or 4, found {kind}"),
                ));
            }
            let nd = usize::from(bin.u8(q + 3, what)?);
            let dims: Vec<usize> = bin
                .slice(q + 4, nd, "parameter dimensions")?
                .iter()
                .map(|&d| usize::from(d))
                .collect();
            let count = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
            let len = count.and_then(|c| c.checked_mul(usize::from(kind.unsigned_abs())));
            let Some(len) = len else {
                return Err(ImportError::format(
                    bin.path,
                    format!("byte {} (parameter {name})", q + 3),
                    "expected sensible dimensions",
                ));
            };
            let data = bin.slice(q + 4 + nd, len, &format!("parameter {name}'s data"))?;
            // The record holds its data: a size that runs past the next record is a
            // corrupt dimension, not data to read.
            let next_record = q + usize::from(next);
            if next != 0 && q + 4 + nd + len > next_record {
                return Err(ImportError::format(
                    bin.path,
                    format!("byte {} (parameter {name})", q + 3),
                    format!(
                        "its dimensions {dims:?} make {len} bytes of data, which run past the \
                         next parameter record at byte {next_record}"
                    ),
                ));
            }
            end = end.max(q + 4 + nd + len);
            raw.push((
                id.unsigned_abs(),
                Param {
                    group: String::new(),
                    name,
                    kind,
                    dims,
                    data,
                },
            ));
        } else {
            return Err(ImportError::format(
                bin.path,
                format!("byte {}", pos + 1),
                format!(
                    "expected a group (negative) or parameter (positive) id for \"{name}\", found 0"
                ),
            ));
        }
        if next == 0 {
            break;
        }
        let next_pos = q + usize::from(next);
        // The last record may point just past the parameter section (some writers do, for
        // 0); farther is an offset gone wrong (a negative one read unsigned), which would
        // silently drop every parameter after it.
        if next_pos > section_end.max(data_offset.unwrap_or(0)) + BLOCK {
            return Err(ImportError::format(
                bin.path,
                format!("byte {q} (offset to the next parameter record)"),
                format!(
                    "{next} points past the parameter section \
                     (which ends at byte {section_end})"
                ),
            ));
        }
        if next_pos <= q + 1 {
            return Err(ImportError::format(
                bin.path,
                format!("byte {q}"),
                format!("expected an offset to the next parameter of 2 or more, found {next}"),
            ));
        }
        pos = next_pos;
    }
    let list = raw
        .into_iter()
        .map(|(gid, mut p)| {
            p.group = groups
                .iter()
                .find(|(id, _)| *id == gid)
                .map(|(_, n)| n.clone())
                .unwrap_or_default();
            p
        })
        .collect();
    Ok(Params {
        proc: bin.proc,
        list,
        end,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    // The writer's round trips through this reader are in `io::c3d_write`.

    #[test]
    fn dec_floats_convert() {
        // VAX F-floating 1.0: exponent 129, fraction 0 → word0 0x4080, word1 0.
        assert_eq!(dec_to_f32([0x80, 0x40, 0, 0]), 1.0);
        assert!(dec_to_f32([0, 0x80, 0, 0]).is_sign_negative());
    }
}
