//! The C3D writer: a [`Take`] as a C3D file for our own exports (the reader is
//! [`crate::mocap::import::c3d`]). Per the C3D spec: Intel processor (type 84), float
//! point storage in millimetres, POINT group parameters (USED, RATE, SCALE, UNITS, LABELS…).

use crate::mocap::import::c3d::{BLOCK, KEY, Processor};
use crate::mocap::{Take, Track};
use glam::DVec3;

/// How point coordinates are stored when writing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Storage {
    /// float32 millimetres.
    Float,
    /// int16 counts of `scale` millimetres (only written by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Int { scale: f32 },
}

/// Encoding numbers for a processor: the inverse of the reader's decoding.
impl Processor {
    /// The processor type byte of the parameter section's head.
    fn byte(self) -> u8 {
        match self {
            Processor::Intel => 84,
            Processor::Dec => 85,
            Processor::Mips => 86,
        }
    }

    /// An int16 word in this processor's byte order.
    fn i16_bytes(self, v: i16) -> [u8; 2] {
        match self {
            Processor::Mips => v.to_be_bytes(),
            _ => v.to_le_bytes(),
        }
    }

    /// A float32 in this processor's byte order and float format.
    fn f32_bytes(self, v: f32) -> [u8; 4] {
        match self {
            Processor::Intel => v.to_le_bytes(),
            Processor::Mips => v.to_be_bytes(),
            Processor::Dec => f32_to_dec(v),
        }
    }
}

/// The inverse of the reader's DEC float decoding for finite values within VAX range
/// (others saturate).
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

/// What the header and the parameters of a file being written both state.
struct Layout {
    proc: Processor,
    /// Points per frame (the take's first 65535 tracks).
    points: usize,
    /// Frames in the take.
    frames: usize,
    /// The frame count as an int16 word (capped at 65535).
    frames_u16: u16,
    /// Frame rate, Hz.
    rate: f32,
    /// Point scale factor (negative: float data).
    scale: f32,
}

/// Write `take` with the given processor and storage (the public writer is Intel/float;
/// the others exist to test the reader).
fn encode(take: &Take, proc: Processor, storage: Storage) -> Vec<u8> {
    let points = take.tracks.len().min(usize::from(u16::MAX));
    let layout = Layout {
        proc,
        points,
        frames: take.frames,
        frames_u16: take.frames.min(usize::from(u16::MAX)) as u16,
        rate: take.rate_hz as f32,
        scale: match storage {
            Storage::Float => -0.1f32,
            Storage::Int { scale } => scale,
        },
    };
    let tracks = &take.tracks[..points];
    let (params, data_block) = parameter_section(&layout, tracks);
    let mut out = header(&layout, data_block);
    out.extend_from_slice(&params);
    write_frames(&mut out, &layout, tracks, storage);
    out.resize(out.len().div_ceil(BLOCK) * BLOCK, 0);
    out
}

/// The header block: parameters from block 2, the point count, frames 1 to
/// `frames_u16`, the first data block, the scale and the rate; no analog values.
fn header(layout: &Layout, data_block: usize) -> Vec<u8> {
    let proc = layout.proc;
    let mut out = vec![0u8; BLOCK];
    out[0] = 2;
    out[1] = KEY;
    let put16 = |out: &mut Vec<u8>, word: usize, v: u16| {
        let b = proc.i16_bytes(v as i16);
        out[2 * (word - 1)..2 * (word - 1) + 2].copy_from_slice(&b);
    };
    put16(&mut out, 2, layout.points as u16);
    put16(&mut out, 3, 0);
    put16(&mut out, 4, 1);
    put16(&mut out, 5, layout.frames_u16);
    put16(&mut out, 6, 0);
    put16(&mut out, 9, data_block as u16);
    put16(&mut out, 10, 0);
    out[12..16].copy_from_slice(&proc.f32_bytes(layout.scale));
    out[20..24].copy_from_slice(&proc.f32_bytes(layout.rate));
    out
}

/// The parameter section padded to whole blocks: its 4-byte head (block count and
/// processor type), then the records with POINT:DATA_START filled in. Also the block
/// number where the data start.
fn parameter_section(layout: &Layout, tracks: &[Track]) -> (Vec<u8>, usize) {
    let proc = layout.proc;
    let (mut records, data_start_at) = parameter_records(layout, tracks);
    let param_len = 4 + records.len();
    let param_blocks = param_len.div_ceil(BLOCK);
    let data_block = 2 + param_blocks;
    let db = proc.i16_bytes(data_block as u16 as i16);
    records[data_start_at..data_start_at + 2].copy_from_slice(&db);
    let mut section = vec![1, KEY, param_blocks.min(255) as u8, proc.byte()];
    section.extend_from_slice(&records);
    section.resize(param_blocks * BLOCK, 0);
    (section, data_block)
}

/// The parameter records of the POINT, ANALOG and TRIAL groups, and the byte position
/// in them of POINT:DATA_START's value (written 0, patched once the section's size is
/// known).
fn parameter_records(layout: &Layout, tracks: &[Track]) -> (Vec<u8>, usize) {
    let frames = layout.frames;
    let labels: Vec<&str> = tracks.iter().map(|t| c3d_label(&t.label)).collect();
    let width = labels.iter().map(|l| l.len()).max().unwrap_or(1).max(1);
    let per_param = (32_000 / width).clamp(1, 255);

    let mut pw = ParamWriter {
        proc: layout.proc,
        buf: Vec::new(),
        offset_fields: Vec::new(),
    };
    pw.group(1, "POINT");
    pw.int(1, "USED", &[layout.points as u16 as i16]);
    pw.int(1, "FRAMES", &[layout.frames_u16 as i16]);
    let data_start_at = pw.buf.len() + 2 + "DATA_START".len() + 2 + 2;
    pw.int(1, "DATA_START", &[0]);
    pw.float(1, "SCALE", layout.scale);
    pw.float(1, "RATE", layout.rate);
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
    (pw.buf, data_start_at)
}

/// Append the point data: for each frame, each track's position (metres in the take,
/// millimetres in the file) and its residual word.
fn write_frames(out: &mut Vec<u8>, layout: &Layout, tracks: &[Track], storage: Storage) {
    for f in 0..layout.frames {
        for t in tracks {
            let mm = t.positions.get(f).copied().flatten().map(|p| p * 1000.0);
            write_point(out, layout.proc, storage, mm);
        }
    }
}

/// Append one point: X, Y, Z in millimetres and residual 0, or zeros and residual −1
/// when the point is missing or cannot be stored.
fn write_point(out: &mut Vec<u8>, proc: Processor, storage: Storage, mm: Option<DVec3>) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::import::c3d::{dec_to_f32, inspect, read};
    use std::path::Path;

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
    fn dec_floats_round_trip() {
        for v in [1.0f32, -2.5, 1234.5678, 1e-20, -3.0e30, 0.0] {
            assert_eq!(dec_to_f32(f32_to_dec(v)), v);
        }
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

    /// A big-endian (MIPS) file's NaN and infinite coordinates are gaps, counted in the
    /// take's gap note, as in an Intel one (tests/mocap_import.rs).
    #[test]
    fn non_finite_big_endian_floats_are_counted_gaps() {
        let take = sample(12);
        let mut bytes = encode(&take, Processor::Mips, Storage::Float);
        let info = inspect(Path::new("x"), &bytes).unwrap();
        let mut mark = |frame: usize, point: usize, axis: usize, v: f32| {
            let at = info.data_offset + (frame * info.points + point) * 16 + 4 * axis;
            bytes[at..at + 4].copy_from_slice(&v.to_be_bytes());
        };
        mark(0, 0, 0, f32::NAN);
        mark(1, 2, 2, f32::NEG_INFINITY);
        mark(2, 1, 1, f32::INFINITY);
        let back = read(Path::new("x"), &bytes, None).unwrap();
        let missing = |f: usize, p: usize| back.tracks[p].positions[f].is_none();
        assert!(missing(0, 0) && missing(1, 2) && missing(2, 1));
        assert!(!missing(0, 1) && !missing(1, 0));
        assert_eq!(
            back.notes,
            ["1 sample written as NaN and 2 written as ±infinity read as gaps"]
        );
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
