//! C3D: the binary motion-capture interchange format (<https://www.c3d.org>), read and
//! written.
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
//!   `None`; non-finite coordinates are also `None`.
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
//! * The frame count is the header's last − first + 1; `POINT:FRAMES` (an int16 that may
//!   be meant unsigned) and `POINT:LONG_FRAMES` / `TRIAL` fields are used when they show
//!   the header overflowed.
//! * **A data section that stops early** (fewer whole frames in the file than declared)
//!   is read up to the last whole frame; the take keeps the declared length with the
//!   frames that are not in the file marked missing, and says so in its notes ([`inspect`]
//!   reports both counts). A file with no whole frame at all is refused. (The Optotrak sample shipped with
//!   ezc3d declares 1149 frames but holds 29.)

use super::LengthUnit;
use crate::mocap::take::{ImportError, Take, Track};
use glam::DVec3;
use std::path::Path;

/// Bytes per C3D block.
const BLOCK: usize = 512;
/// The key in the header's second byte.
const KEY: u8 = 0x50;

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

    fn byte(self) -> u8 {
        match self {
            Processor::Intel => 84,
            Processor::Dec => 85,
            Processor::Mips => 86,
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

    fn i16_bytes(self, v: i16) -> [u8; 2] {
        match self {
            Processor::Mips => v.to_be_bytes(),
            _ => v.to_le_bytes(),
        }
    }

    fn f32_bytes(self, v: f32) -> [u8; 4] {
        match self {
            Processor::Intel => v.to_le_bytes(),
            Processor::Mips => v.to_be_bytes(),
            Processor::Dec => f32_to_dec(v),
        }
    }
}

/// A VAX F-floating value as stored in a DEC C3D file. Its 16-bit words are swapped
/// relative to an IEEE little-endian float; the fraction has the same bits, but the
/// hidden bit stands for 0.5 rather than 1 and the exponent bias is 128, so the value is
/// the word-swapped IEEE value / 4. Exponent 0 is zero (with the sign set, a "reserved
/// operand", returned as −0 so a residual reads as invalid).
fn dec_to_f32(b: [u8; 4]) -> f32 {
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

/// The inverse of [`dec_to_f32`] for finite values within VAX range (others saturate).
fn f32_to_dec(v: f32) -> [u8; 4] {
    let bits = v.to_bits();
    let exp = (bits >> 23) & 0xff;
    if exp == 0 {
        return [0; 4];
    }
    let vax_exp = (exp + 2).min(255);
    let vbits = (bits & 0x8000_0000) | (vax_exp << 23) | (bits & 0x7f_ffff);
    let c = vbits.to_le_bytes();
    [c[2], c[3], c[0], c[1]]
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
    let (point_size, value_size) = if info.float_data { (16, 4) } else { (8, 2) };
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
            let v = DVec3::from_array(xyz) * metres;
            track
                .positions
                .push((!invalid && v.is_finite()).then_some(v));
        }
    }
    let mut notes = Vec::new();
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
    Ok(Take {
        source: path.to_path_buf(),
        rate_hz: info.rate_hz,
        frames,
        file_unit: unit.symbol().to_string(),
        tracks,
        notes,
    })
}

/// Header, parameters and layout.
fn parse(path: &Path, bytes: &[u8]) -> Result<(C3dInfo, Processor), ImportError> {
    let err = |place: String, msg: String| ImportError::format(path, place, msg);
    let probe = Bin {
        path,
        bytes,
        proc: Processor::Intel,
    };
    let param_block = probe.u8(0, "the C3D header")?;
    let key = probe.u8(1, "the C3D header")?;
    if key != KEY {
        return Err(err(
            "byte 1".into(),
            format!("expected the C3D key 0x50, found 0x{key:02x}: not a C3D file"),
        ));
    }
    if param_block == 0 {
        return Err(err(
            "byte 0".into(),
            "expected the parameter section's block number (1 or more), found 0".into(),
        ));
    }
    let param_start = (usize::from(param_block) - 1) * BLOCK;
    let proc_off = param_start + 3;
    let proc_byte = probe.u8(proc_off, "the parameter section header")?;
    let proc = Processor::from_byte(proc_byte).ok_or_else(|| {
        err(
            format!("byte {proc_off} (processor type)"),
            format!("expected 84 (Intel), 85 (DEC) or 86 (MIPS), found {proc_byte}"),
        )
    })?;
    let bin = Bin { path, bytes, proc };

    // Header.
    let hdr = "the C3D header";
    let h_points = usize::from(bin.u16(2, hdr)?);
    let h_analog_total = usize::from(bin.u16(4, hdr)?);
    let h_first = bin.u16(6, hdr)?;
    let h_last = bin.u16(8, hdr)?;
    let h_scale = f64::from(bin.f32(12, hdr)?);
    let h_data_block = usize::from(bin.u16(16, hdr)?);
    let h_analog_samples = usize::from(bin.u16(18, hdr)?);
    let h_rate = f64::from(bin.f32(20, hdr)?);

    let data_hint = (h_data_block > usize::from(param_block)).then(|| (h_data_block - 1) * BLOCK);
    let params = parse_params(&bin, param_start + 4, data_hint)?;

    // Points.
    let points = match params.first_count("POINT", "USED") {
        Some(used) if used != h_points => {
            return Err(err(
                "parameter POINT:USED".into(),
                format!(
                    "expected the header's point count {h_points} (word 2), found {used}: the \
                     file is inconsistent"
                ),
            ));
        }
        _ => h_points,
    };

    // Rate.
    let rate_hz = match params.first_number("POINT", "RATE") {
        Some(r) if r.is_finite() && r > 0.0 => r,
        _ if h_rate.is_finite() && h_rate > 0.0 => h_rate,
        other => {
            return Err(err(
                "parameter POINT:RATE".into(),
                format!(
                    "expected a frame rate above 0 Hz (here or in header words 11–12), found \
                     {}",
                    other.unwrap_or(h_rate)
                ),
            ));
        }
    };

    // Storage and scale: the header's sign decides float or int (as most readers do).
    let p_scale = params.first_number("POINT", "SCALE");
    let sign_source = if h_scale.is_finite() && h_scale != 0.0 {
        h_scale
    } else {
        p_scale.unwrap_or(h_scale)
    };
    let float_data = sign_source < 0.0;
    let scale = match p_scale {
        Some(s) if s.is_finite() && s != 0.0 => s,
        _ => sign_source,
    };
    if !float_data && points > 0 && !(scale.is_finite() && scale != 0.0) {
        return Err(err(
            "parameter POINT:SCALE".into(),
            format!("expected a non-zero scale factor for integer point data, found {scale}"),
        ));
    }

    // Analog values per frame (skipped, but they set the frame size).
    let analog_values_per_frame = match params.first_count("ANALOG", "USED") {
        Some(0) => 0,
        Some(used) => {
            let per = if h_analog_samples > 0 {
                h_analog_samples
            } else {
                match params.first_number("ANALOG", "RATE") {
                    Some(ar) if ar.is_finite() && ar > 0.0 => (ar / rate_hz).round() as usize,
                    _ => 0,
                }
            };
            if per == 0 {
                h_analog_total
            } else {
                used.checked_mul(per).ok_or_else(|| {
                    err(
                        "parameter ANALOG:USED".into(),
                        format!("expected a sensible channel count, found {used}"),
                    )
                })?
            }
        }
        None => h_analog_total,
    };

    // Data start.
    let data_block = if h_data_block >= 2 {
        h_data_block
    } else {
        params.first_count("POINT", "DATA_START").unwrap_or(0)
    };
    if data_block < 2 {
        return Err(err(
            "header word 9 (byte 16)".into(),
            format!("expected the first data block (2 or more), found {h_data_block}"),
        ));
    }
    let data_offset = (data_block - 1) * BLOCK;
    if data_offset > bytes.len() {
        return Err(err(
            "header word 9 (byte 16)".into(),
            format!(
                "expected the data to start inside the file, found block {data_block} (byte \
                 {data_offset}) in a file of {} bytes: truncated?",
                bytes.len()
            ),
        ));
    }

    // Frames declared.
    let header_frames = if h_last >= h_first {
        usize::from(h_last - h_first) + 1
    } else {
        0
    };
    let mut declared = match params.first_count("POINT", "FRAMES") {
        Some(p) if p > header_frames => p,
        _ => header_frames,
    };
    let long = params.first_count("POINT", "LONG_FRAMES").or_else(|| {
        let start = params.long_field("TRIAL", "ACTUAL_START_FIELD")?;
        let end = params.long_field("TRIAL", "ACTUAL_END_FIELD")?;
        (end >= start).then(|| (end - start) as usize + 1)
    });
    if let Some(l) = long.filter(|&l| l > usize::from(u16::MAX)) {
        declared = declared.max(l);
    }

    // Frames present.
    let (point_size, value_size) = if float_data {
        (16usize, 4usize)
    } else {
        (8, 2)
    };
    let frame_size = points
        .checked_mul(point_size)
        .and_then(|p| {
            analog_values_per_frame
                .checked_mul(value_size)
                .and_then(|a| p.checked_add(a))
        })
        .ok_or_else(|| err("header".into(), "expected a sensible frame size".into()))?;
    let frames = if frame_size == 0 || points == 0 {
        declared
    } else {
        let whole = (bytes.len() - data_offset) / frame_size;
        if whole == 0 && declared > 0 {
            return Err(err(
                format!("byte {data_offset}"),
                format!(
                    "expected {declared} frames of {frame_size} bytes ({points} points, \
                     {analog_values_per_frame} analog values), found only {} bytes of data: \
                     truncated?",
                    bytes.len() - data_offset
                ),
            ));
        }
        whole.min(declared)
    };

    // Labels.
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

    let unit = params
        .strings("POINT", "UNITS")
        .and_then(|u| u.into_iter().next())
        .unwrap_or_default();

    Ok((
        C3dInfo {
            processor: proc,
            points,
            rate_hz,
            first_frame: u32::from(h_first),
            declared_frames: declared,
            frames,
            float_data,
            scale,
            unit,
            analog_values_per_frame,
            data_offset,
            labels,
        },
        proc,
    ))
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
    })
}

/// How point coordinates are stored when writing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Storage {
    /// float32 millimetres.
    Float,
    /// int16 counts of `scale` millimetres (only written by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Int { scale: f32 },
}

/// Write `take` as a C3D file: Intel processor, float data, millimetres, no analog
/// channels. Labels longer than 255 bytes are cut; rigid-body rotations are not stored
/// (C3D points have none); `None` samples are written as invalid points (residual −1).
pub fn write_c3d(take: &Take) -> Vec<u8> {
    encode(take, Processor::Intel, Storage::Float)
}

/// Builds a parameter section.
struct ParamWriter {
    proc: Processor,
    buf: Vec<u8>,
    /// Byte position of each record's next-offset field.
    offset_fields: Vec<usize>,
}

impl ParamWriter {
    fn record_head(&mut self, id: i8, name: &str) {
        if let Some(&last) = self.offset_fields.last() {
            let off = (self.buf.len() - last) as i16;
            let b = self.proc.i16_bytes(off);
            self.buf[last..last + 2].copy_from_slice(&b);
        }
        self.buf.push(name.len() as u8);
        self.buf.push(id as u8);
        self.buf.extend_from_slice(name.as_bytes());
        self.offset_fields.push(self.buf.len());
        self.buf.extend_from_slice(&[0, 0]);
    }

    fn group(&mut self, id: i8, name: &str) {
        self.record_head(-id, name);
        self.buf.push(0); // no description
    }

    fn param(&mut self, group: i8, name: &str, kind: i8, dims: &[u8], data: &[u8]) {
        self.record_head(group, name);
        self.buf.push(kind as u8);
        self.buf.push(dims.len() as u8);
        self.buf.extend_from_slice(dims);
        self.buf.extend_from_slice(data);
        self.buf.push(0); // no description
    }

    fn int(&mut self, group: i8, name: &str, values: &[i16]) {
        let data: Vec<u8> = values
            .iter()
            .flat_map(|&v| self.proc.i16_bytes(v))
            .collect();
        let dims: &[u8] = if values.len() == 1 {
            &[]
        } else {
            &[values.len() as u8]
        };
        self.param(group, name, 2, dims, &data);
    }

    fn float(&mut self, group: i8, name: &str, v: f32) {
        let data = self.proc.f32_bytes(v);
        self.param(group, name, 4, &[], &data);
    }

    fn strings(&mut self, group: i8, name: &str, values: &[&str], width: usize) {
        let mut data = Vec::with_capacity(width * values.len());
        for v in values {
            data.extend_from_slice(v.as_bytes());
            data.resize(data.len() + width - v.len(), b' ');
        }
        self.param(group, name, -1, &[width as u8, values.len() as u8], &data);
    }
}

/// A label cut to at most 255 bytes at a character boundary.
fn c3d_label(label: &str) -> &str {
    let mut end = label.len().min(255);
    while !label.is_char_boundary(end) {
        end -= 1;
    }
    &label[..end]
}

/// Write `take` with the given processor and storage (the public writer is Intel/float;
/// the others exist to test the reader).
fn encode(take: &Take, proc: Processor, storage: Storage) -> Vec<u8> {
    let points = take.tracks.len().min(usize::from(u16::MAX));
    let frames = take.frames;
    let frames_u16 = frames.min(usize::from(u16::MAX)) as u16;
    let rate = take.rate_hz as f32;
    let scale = match storage {
        Storage::Float => -0.1f32,
        Storage::Int { scale } => scale,
    };
    let labels: Vec<&str> = take.tracks[..points]
        .iter()
        .map(|t| c3d_label(&t.label))
        .collect();
    let width = labels.iter().map(|l| l.len()).max().unwrap_or(1).max(1);
    let per_param = (32_000 / width).clamp(1, 255);

    // Parameters; DATA_START is patched in once the section's size is known.
    let mut pw = ParamWriter {
        proc,
        buf: Vec::new(),
        offset_fields: Vec::new(),
    };
    pw.group(1, "POINT");
    pw.int(1, "USED", &[points as u16 as i16]);
    pw.int(1, "FRAMES", &[frames_u16 as i16]);
    let data_start_at = pw.buf.len() + 2 + "DATA_START".len() + 2 + 2;
    pw.int(1, "DATA_START", &[0]);
    pw.float(1, "SCALE", scale);
    pw.float(1, "RATE", rate);
    pw.strings(1, "UNITS", &["mm"], 2);
    let blanks = vec![""; labels.len()];
    for (base, values, w) in [("LABELS", &labels, width), ("DESCRIPTIONS", &blanks, 1)] {
        if values.is_empty() {
            pw.strings(1, base, &[], w);
        }
        for (i, chunk) in values.chunks(per_param).enumerate() {
            let name = if i == 0 {
                base.to_string()
            } else {
                format!("{base}{}", i + 1)
            };
            pw.strings(1, &name, chunk, w);
        }
    }
    if frames > usize::from(u16::MAX) {
        pw.float(1, "LONG_FRAMES", frames as f32);
    }
    pw.group(2, "ANALOG");
    pw.int(2, "USED", &[0]);
    pw.float(2, "RATE", 0.0); // no analog channels: 0 samples per frame, as in header word 10
    pw.group(3, "TRIAL");
    pw.int(3, "ACTUAL_START_FIELD", &[1, 0]);
    let end = frames.min(u32::MAX as usize) as u32;
    pw.int(
        3,
        "ACTUAL_END_FIELD",
        &[(end & 0xffff) as u16 as i16, (end >> 16) as u16 as i16],
    );
    // The last record's offset stays 0; a zero byte after it ends the section too.
    pw.buf.push(0);

    let param_len = 4 + pw.buf.len();
    let param_blocks = param_len.div_ceil(BLOCK);
    let data_block = 2 + param_blocks;
    let db = proc.i16_bytes(data_block as u16 as i16);
    pw.buf[data_start_at..data_start_at + 2].copy_from_slice(&db);

    // Header.
    let mut out = vec![0u8; BLOCK];
    out[0] = 2;
    out[1] = KEY;
    let put16 = |out: &mut Vec<u8>, word: usize, v: u16| {
        let b = proc.i16_bytes(v as i16);
        out[2 * (word - 1)..2 * (word - 1) + 2].copy_from_slice(&b);
    };
    put16(&mut out, 2, points as u16);
    put16(&mut out, 3, 0);
    put16(&mut out, 4, 1);
    put16(&mut out, 5, frames_u16);
    put16(&mut out, 6, 0);
    put16(&mut out, 9, data_block as u16);
    put16(&mut out, 10, 0);
    out[12..16].copy_from_slice(&proc.f32_bytes(scale));
    out[20..24].copy_from_slice(&proc.f32_bytes(rate));

    // Parameter section.
    out.extend_from_slice(&[1, KEY, param_blocks.min(255) as u8, proc.byte()]);
    out.extend_from_slice(&pw.buf);
    out.resize((data_block - 1) * BLOCK, 0);

    // Data.
    for f in 0..frames {
        for t in &take.tracks[..points] {
            let mm = t.positions.get(f).copied().flatten().map(|p| p * 1000.0);
            match storage {
                Storage::Float => {
                    let (xyz, r) = match mm.filter(|v| v.is_finite()) {
                        Some(v) => (v.as_vec3().to_array(), 0.0f32),
                        None => ([0.0; 3], -1.0),
                    };
                    for c in xyz {
                        out.extend_from_slice(&proc.f32_bytes(c));
                    }
                    out.extend_from_slice(&proc.f32_bytes(r));
                }
                Storage::Int { scale } => {
                    let counts = mm
                        .map(|v| (v / f64::from(scale)).round())
                        .filter(|c| c.is_finite() && c.abs().max_element() <= f64::from(i16::MAX));
                    let (xyz, r) = match counts {
                        Some(c) => ([c.x as i16, c.y as i16, c.z as i16], 0i16),
                        None => ([0; 3], -1),
                    };
                    for c in xyz {
                        out.extend_from_slice(&proc.i16_bytes(c));
                    }
                    out.extend_from_slice(&proc.i16_bytes(r));
                }
            }
        }
    }
    out.resize(out.len().div_ceil(BLOCK) * BLOCK, 0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(frames: usize) -> Take {
        let track = |label: &str, k: f64| Track {
            label: label.into(),
            positions: (0..frames)
                .map(|f| {
                    (f % 7 != 3).then(|| DVec3::new(0.5 + 0.01 * f as f64, -1.25 * k, 0.875 + k))
                })
                .collect(),
            rotations: Vec::new(),
        };
        Take {
            source: "mem.c3d".into(),
            rate_hz: 240.0,
            frames,
            file_unit: "m".into(),
            tracks: vec![
                track("StickL:Tip", 0.1),
                track("StickR:Tip", 0.2),
                track("Ü", 0.3),
            ],
            notes: Vec::new(),
        }
    }

    fn close(a: &Take, b: &Take, tol: f64) {
        assert_eq!(a.labels(), b.labels());
        assert_eq!(a.frames, b.frames);
        assert!((a.rate_hz - b.rate_hz).abs() < 1e-9);
        for (ta, tb) in a.tracks.iter().zip(&b.tracks) {
            for (pa, pb) in ta.positions.iter().zip(&tb.positions) {
                match (pa, pb) {
                    (Some(x), Some(y)) => assert!(x.distance(*y) < tol, "{x} vs {y}"),
                    (None, None) => {}
                    _ => panic!("{pa:?} vs {pb:?}"),
                }
            }
        }
    }

    #[test]
    fn dec_floats_convert() {
        // VAX F-floating 1.0: exponent 129, fraction 0 → word0 0x4080, word1 0.
        assert_eq!(dec_to_f32([0x80, 0x40, 0, 0]), 1.0);
        for v in [1.0f32, -2.5, 1234.5678, 1e-20, -3.0e30, 0.0] {
            assert_eq!(dec_to_f32(f32_to_dec(v)), v);
        }
        assert!(dec_to_f32([0, 0x80, 0, 0]).is_sign_negative());
    }

    #[test]
    fn every_processor_and_storage_round_trips() {
        let take = sample(40);
        for proc in [Processor::Intel, Processor::Dec, Processor::Mips] {
            for storage in [Storage::Float, Storage::Int { scale: 0.05 }] {
                let bytes = encode(&take, proc, storage);
                let info = inspect(Path::new("x"), &bytes).unwrap();
                assert_eq!(info.processor, proc);
                assert_eq!(info.float_data, storage == Storage::Float);
                let back = read(Path::new("x"), &bytes, None).unwrap();
                assert_eq!(back.file_unit, "mm");
                close(&take, &back, 1e-4);
            }
        }
    }

    #[test]
    fn many_labels_and_long_takes() {
        let mut take = sample(3);
        let t0 = take.tracks[0].clone();
        take.tracks = (0..300)
            .map(|i| Track {
                label: format!("marker_with_a_long_name_{i:03}"),
                ..t0.clone()
            })
            .collect();
        let back = read(Path::new("x"), &write_c3d(&take), None).unwrap();
        close(&take, &back, 1e-6);

        let mut long = sample(70_000);
        long.tracks.truncate(1);
        let bytes = write_c3d(&long);
        let info = inspect(Path::new("x"), &bytes).unwrap();
        assert_eq!(info.declared_frames, 70_000);
        let back = read(Path::new("x"), &bytes, None).unwrap();
        close(&long, &back, 1e-4);
    }

    #[test]
    fn short_data_reads_whole_frames_and_empty_data_is_refused() {
        let take = sample(10);
        let bytes = write_c3d(&take);
        let info = inspect(Path::new("x"), &bytes).unwrap();
        let frame = 3 * 16;
        let cut = &bytes[..info.data_offset + 4 * frame + 5];
        let back = read(Path::new("x"), cut, None).unwrap();
        assert_eq!(back.frames, 10, "the declared length is kept");
        assert!(
            back.tracks
                .iter()
                .all(|t| t.positions[4..].iter().all(Option::is_none))
        );
        assert!(
            back.tracks
                .iter()
                .any(|t| t.positions[..4].iter().any(Option::is_some))
        );
        assert_eq!(back.notes.len(), 1);
        let e = read(Path::new("x"), &bytes[..info.data_offset + 5], None).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
    }

    #[test]
    fn bad_headers_are_refused_with_the_place() {
        let bytes = write_c3d(&sample(5));
        let p = Path::new("x.c3d");
        let mut b = bytes.clone();
        b[1] = 0x51;
        assert!(
            read(p, &b, None)
                .unwrap_err()
                .to_string()
                .contains("byte 1")
        );
        let mut b = bytes.clone();
        b[512 + 3] = 90;
        assert!(
            read(p, &b, None)
                .unwrap_err()
                .to_string()
                .contains("processor type")
        );
        let mut b = bytes.clone();
        b[2] = 9;
        assert!(
            read(p, &b, None)
                .unwrap_err()
                .to_string()
                .contains("POINT:USED")
        );
        assert!(
            read(p, &bytes[..700], None)
                .unwrap_err()
                .to_string()
                .contains("byte")
        );
        assert!(read(p, &[], None).is_err());
    }
}
