//! Where a C3D file's point data start and how many frames they hold, when the header
//! and the parameters disagree.
//!
//! * **Data start**: header word 9 (bytes 16–17) and `POINT:DATA_START` both give the
//!   1-based 512-byte block of the first frame. Writers that patch one and not the other
//!   leave them apart; `POINT:DATA_START` is taken when it is sane (after the parameter
//!   records, inside the file), else the header's, with a note naming both blocks.
//! * **Frame count**: the header's last − first + 1 (16-bit words), `POINT:FRAMES`
//!   when larger, `POINT:LONG_FRAMES` or the `TRIAL` start and end fields when above
//!   65535. Without those last, a take over 65535 frames shows as a header whose last
//!   frame is clamped to 65535 or whose count wrapped past 65535; the count is then
//!   taken from the data section's whole frames (a wrapped count by whole turns of
//!   65536, a clamped one less the zero padding of the last block), with a note.

use super::{BLOCK, Bin, Header, Params, block_offset, value_sizes};
use crate::mocap::take::ImportError;

/// Byte offset of the first frame: `POINT:DATA_START` when sane, else header word 9
/// (else an error); a disagreement between the two is noted in `notes`.
pub(super) fn data_offset(
    bin: &Bin,
    params: &Params,
    h: &Header,
    param_block: usize,
    notes: &mut Vec<String>,
) -> Result<usize, ImportError> {
    let len = bin.bytes.len();
    let sane = |block: usize| {
        block >= 2
            && block > param_block
            && block_offset(block) >= params.end
            && block_offset(block) < len
    };
    let param_start = params.first_count("POINT", "DATA_START");
    if let Some(ds) = param_start.filter(|&ds| sane(ds)) {
        if ds != h.data_block {
            notes.push(format!(
                "the header gives data block {} (word 9), POINT:DATA_START block {ds}; read \
                 from block {ds} (the header's {})",
                h.data_block,
                if sane(h.data_block) {
                    "disagrees"
                } else {
                    "is not after the parameters inside the file"
                }
            ));
        }
        return Ok(block_offset(ds));
    }
    let data_block = if h.data_block >= 2 {
        h.data_block
    } else {
        param_start.unwrap_or(0)
    };
    let place = "header word 9 (byte 16)";
    if data_block < 2 {
        return Err(ImportError::format(
            bin.path,
            place,
            format!(
                "expected the first data block (2 or more), found {}",
                h.data_block
            ),
        ));
    }
    let data_offset = block_offset(data_block);
    if data_offset > len {
        return Err(ImportError::format(
            bin.path,
            place,
            format!(
                "expected the data to start inside the file, found block {data_block} (byte \
                 {data_offset}) in a file of {len} bytes: truncated?"
            ),
        ));
    }
    if let Some(ds) = param_start.filter(|&ds| ds != data_block) {
        notes.push(format!(
            "the header gives data block {data_block} (word 9), POINT:DATA_START block {ds}; \
             read from block {data_block} (POINT:DATA_START is not after the parameters \
             inside the file)"
        ));
    }
    Ok(data_offset)
}

/// Frames declared: the header's last − first + 1, or `POINT:FRAMES` when larger, or
/// `POINT:LONG_FRAMES` (else the TRIAL start and end fields) when above 65535. Also
/// whether a long count was given by either of those last.
pub(super) fn declared_frames(params: &Params, h: &Header) -> (usize, bool) {
    let header_frames = if h.last >= h.first {
        usize::from(h.last - h.first) + 1
    } else {
        0
    };
    let declared = match params.first_count("POINT", "FRAMES") {
        Some(p) if p > header_frames => p,
        _ => header_frames,
    };
    let long = params.first_count("POINT", "LONG_FRAMES").or_else(|| {
        let start = params.long_field("TRIAL", "ACTUAL_START_FIELD")?;
        let end = params.long_field("TRIAL", "ACTUAL_END_FIELD")?;
        (end >= start).then(|| (end - start) as usize + 1)
    });
    match long.filter(|&l| l > usize::from(u16::MAX)) {
        Some(l) => (declared.max(l), true),
        None => (declared, false),
    }
}

/// What the data section holds.
pub(super) struct Present {
    /// Frames declared, corrected for a clamped or wrapped 16-bit count.
    pub declared: usize,
    /// Whole frames read (≤ `declared`).
    pub frames: usize,
}

/// The frame layout: bytes per frame of `points` points and `analog` analog values.
pub(super) struct FrameShape {
    pub points: usize,
    pub analog: usize,
    pub float_data: bool,
}

/// Whole frames present in the data section from `data_offset`, at most `declared`
/// (`declared` when frames have no size); a data section without one whole frame is
/// refused. Without a long count (`long_known` false), a header whose last frame is
/// 65535 or whose count is short of the data by whole turns of 65536 gets the count
/// from the data, with a note.
pub(super) fn frames_present(
    bin: &Bin,
    data_offset: usize,
    shape: &FrameShape,
    h: &Header,
    (declared, long_known): (usize, bool),
    notes: &mut Vec<String>,
) -> Result<Present, ImportError> {
    let FrameShape {
        points,
        analog,
        float_data,
    } = *shape;
    let (point_size, value_size) = value_sizes(float_data);
    let frame_size = points
        .checked_mul(point_size)
        .and_then(|p| {
            analog
                .checked_mul(value_size)
                .and_then(|a| p.checked_add(a))
        })
        .ok_or_else(|| ImportError::format(bin.path, "header", "expected a sensible frame size"))?;
    if frame_size == 0 || points == 0 {
        return Ok(Present {
            declared,
            frames: declared,
        });
    }
    let data_len = bin.bytes.len() - data_offset;
    let whole = data_len / frame_size;
    if whole == 0 && declared > 0 {
        return Err(ImportError::format(
            bin.path,
            format!("byte {data_offset}"),
            format!(
                "expected {declared} frames of {frame_size} bytes ({points} points, \
                 {analog} analog values), found only {data_len} bytes of data: truncated?"
            ),
        ));
    }
    let declared = if long_known {
        declared
    } else {
        uncapped_count(bin, frame_size, data_len, declared, h, notes)
    };
    Ok(Present {
        declared,
        frames: whole.min(declared),
    })
}

/// The frame count of a take over 65535 frames written without `POINT:LONG_FRAMES` or
/// `TRIAL` fields: the data's whole frames when the header's last frame is clamped at
/// 65535 (less trailing all-zero frames in the last block's padding), or the declared
/// count plus the whole turns of 65536 the data hold beyond it (a wrapped count);
/// otherwise `declared`.
fn uncapped_count(
    bin: &Bin,
    frame_size: usize,
    data_len: usize,
    declared: usize,
    h: &Header,
    notes: &mut Vec<String>,
) -> usize {
    const TURN: usize = 1 << 16;
    let whole = data_len / frame_size;
    let (count, why) = if h.last == u16::MAX {
        let padding = bin.bytes.iter().rev().take_while(|&&b| b == 0).count();
        let partial = data_len - whole * frame_size;
        let count = whole - padding.min(BLOCK - 1).saturating_sub(partial) / frame_size;
        (
            count,
            "its last frame 65535 is the most a 16-bit word holds",
        )
    } else {
        let turns = whole.saturating_sub(declared) / TURN;
        (declared + turns * TURN, "a 16-bit count wraps past 65535")
    };
    if count <= declared {
        return declared;
    }
    notes.push(format!(
        "the header declares {declared} frames ({why}) and neither POINT:LONG_FRAMES nor \
         TRIAL:ACTUAL_START_FIELD/ACTUAL_END_FIELD gives the count; the data section holds \
         {count} whole frames: all are read"
    ));
    count
}
