//! The writers of each layout: Motive CSV, Vicon CSV, Qualisys 6D TSV, TRC and the vendor
//! CSV, from the lab view of a take.

use super::*;

/// The file's text.
pub(super) fn write_layout(out: &OutTake, style: &LabStyle) -> String {
    let mut s = String::new();
    if let Some(title) = style
        .title
        .as_ref()
        .filter(|_| style.layout != Layout::Vendor)
    {
        s.push_str(title);
        s.push('\n');
    }
    let body = match style.layout {
        Layout::Motive => motive(out, style),
        Layout::Vicon => vicon(out, style),
        Layout::Qualisys => qualisys(out),
        Layout::Trc => trc(out, style),
        Layout::Vendor => vendor(out, style),
    };
    s + &body
}

/// `v` with `decimals` decimals.
pub(super) fn num(v: f64, decimals: usize) -> String {
    format!("{v:.decimals$}")
}

/// A rate as labs write it: whole numbers without decimals.
pub(super) fn rate_text(rate_hz: f64) -> String {
    if rate_hz.fract() == 0.0 {
        format!("{rate_hz:.0}")
    } else {
        format!("{rate_hz}")
    }
}

/// Decimals of a position in `unit` for a layout writing `mm` decimals in millimetres.
pub(super) fn decimals(layout: Layout, unit: LengthUnit) -> usize {
    layout.mm_decimals()
        + match unit {
            LengthUnit::Millimetre => 0,
            LengthUnit::Centimetre => 1,
            LengthUnit::Metre => 3,
        }
}

/// The x, y, z cells of every track at frame `f`, in track order.
fn marker_cells(out: &OutTake, f: usize, scale: f64, decimals: usize) -> Vec<String> {
    out.tracks
        .iter()
        .flat_map(|t| xyz_cells(t.positions[f], scale, decimals))
        .collect()
}

/// A position's three cells in the file unit (empty when missing).
pub(super) fn xyz_cells(p: Option<DVec3>, scale: f64, decimals: usize) -> [String; 3] {
    match p {
        Some(p) => (p * scale).to_array().map(|v| num(v, decimals)),
        None => Default::default(),
    }
}

/// A plausible per-frame fit error for a rigid body, m (deterministic).
pub(super) fn fit_error_m(frame: usize, body: usize) -> f64 {
    let phase = (frame as f64 * 0.37 + body as f64 * 1.3).sin();
    0.0002 + 0.00015 * phase * phase
}

/// One column of a Motive export: Type, Name, ID, kind and axis headers.
pub(super) struct MotiveColumn {
    pub(super) ty: &'static str,
    pub(super) name: String,
    pub(super) id: String,
    pub(super) kind: &'static str,
    pub(super) axis: &'static str,
}

/// The header columns of one Motive track.
pub(super) fn motive_columns(t: &OutTrack, marker_no: usize) -> Vec<MotiveColumn> {
    let col = |ty, id: &str, kind, axis| MotiveColumn {
        ty,
        name: t.label.clone(),
        id: id.to_string(),
        kind,
        axis,
    };
    let position = |ty, id: &str| ["X", "Y", "Z"].map(|a| col(ty, id, "Position", a));
    match t.kind {
        Kind::Body => {
            let id = t.body.to_string();
            let mut cols: Vec<_> = ["X", "Y", "Z", "W"]
                .map(|a| col("Rigid Body", &id, "Rotation", a))
                .into_iter()
                .collect();
            cols.extend(position("Rigid Body", &id));
            cols.push(col("Rigid Body", &id, "Mean Marker Error", ""));
            cols
        }
        Kind::ClusterMarker => {
            let id = format!("{}:{marker_no}", t.body);
            let mut cols: Vec<_> = position("Rigid Body Marker", &id).into_iter().collect();
            cols.push(col("Rigid Body Marker", &id, "Marker Quality", ""));
            cols
        }
        Kind::Marker => position("Marker", &marker_no.to_string())
            .into_iter()
            .collect(),
    }
}

/// The cells of one Motive track in frame `f`.
pub(super) fn motive_cells(t: &OutTrack, f: usize, scale: f64, d: usize) -> Vec<String> {
    let p = t.positions[f];
    let mut cells: Vec<String> = Vec::new();
    if t.kind == Kind::Body {
        match t.rotations[f] {
            Some(q) => cells.extend(q.to_array().map(|v| num(v, 6))),
            None => cells.extend(std::iter::repeat_n(String::new(), 4)),
        }
    }
    cells.extend(xyz_cells(p, scale, d));
    match (t.kind, p) {
        (Kind::Body, Some(_)) => cells.push(num(fit_error_m(f, t.body) * scale, d)),
        (Kind::ClusterMarker, Some(_)) => cells.push(num(1.0 - 50.0 * fit_error_m(f, t.body), 6)),
        (Kind::Marker, _) => {}
        _ => cells.push(String::new()),
    }
    cells
}

/// Motive CSV 1.23 (see the module doc).
pub(super) fn motive(out: &OutTake, style: &LabStyle) -> String {
    let unit = style.written_unit();
    let unit_name = match unit {
        LengthUnit::Millimetre => "Millimeters",
        LengthUnit::Centimetre => "Centimeters",
        LengthUnit::Metre => "Meters",
    };
    let r = out.rate_hz;
    let mut s = format!(
        "Format Version,1.23,Take Name,{},Take Notes,,Capture Frame Rate,{r:.6},Export Frame \
         Rate,{r:.6},Capture Start Time,2026-11-30 10.21.07.000 AM,Capture Start Frame,0,Total \
         Frames in Take,{},Total Exported Frames,{},Rotation Type,Quaternion,Length \
         Units,{unit_name},Coordinate Space,Global\n\n",
        out.name,
        out.frames,
        out.rows.len()
    );
    let mut marker_no = 0;
    let columns: Vec<MotiveColumn> = out
        .tracks
        .iter()
        .flat_map(|t| {
            marker_no = if t.kind == Kind::Body {
                0
            } else {
                marker_no + 1
            };
            motive_columns(t, marker_no)
        })
        .collect();
    let header = |first: &str, cell: &dyn Fn(&MotiveColumn) -> &str| {
        let cells: Vec<&str> = columns.iter().map(cell).collect();
        format!("{first},{}\n", cells.join(","))
    };
    s += &header(",Type", &|c| c.ty);
    s += &header(",Name", &|c| &c.name);
    s += &header(",ID", &|c| &c.id);
    s += &header(",", &|c| c.kind);
    s += &header("Frame,Time (Seconds)", &|c| c.axis);
    let (scale, d) = (1.0 / unit.metres(), decimals(Layout::Motive, unit));
    for &f in &out.rows {
        let cells: Vec<String> = out
            .tracks
            .iter()
            .flat_map(|t| motive_cells(t, f, scale, d))
            .collect();
        let _ = writeln!(s, "{f},{:.6},{}", f as f64 / r, cells.join(","));
    }
    s
}

/// Vicon Nexus CSV, `Trajectories` section (see the module doc).
pub(super) fn vicon(out: &OutTake, style: &LabStyle) -> String {
    let unit = style.written_unit();
    let mut s = format!("Trajectories\n{}\n", rate_text(out.rate_hz));
    let labels: Vec<String> = out
        .tracks
        .iter()
        .map(|t| format!("{},,", t.label))
        .collect();
    let _ = writeln!(s, ",,{}", labels.join(","));
    let axes = vec!["X,Y,Z"; out.tracks.len()].join(",");
    let _ = writeln!(s, "Frame,Sub Frame,{axes}");
    let units = vec![format!("{0},{0},{0}", unit.symbol()); out.tracks.len()].join(",");
    let _ = writeln!(s, ",,{units}");
    let (scale, d) = (1.0 / unit.metres(), decimals(Layout::Vicon, unit));
    for &f in &out.rows {
        let _ = writeln!(
            s,
            "{},0,{}",
            f + 1,
            marker_cells(out, f, scale, d).join(",")
        );
    }
    s
}

/// QTM's roll, pitch and yaw of `q` (R = Rx(roll)·Ry(pitch)·Rz(yaw)), degrees.
pub fn qualisys_angles_deg(q: DQuat) -> [f64; 3] {
    let (roll, pitch, yaw) = q.to_euler(EulerRot::XYZ);
    [roll, pitch, yaw].map(f64::to_degrees)
}

/// The vendor layout's Z, Y, X Euler angles of `q` (R = Rz·Ry·Rx), radians.
pub fn vendor_angles_rad(q: DQuat) -> [f64; 3] {
    let (z, y, x) = q.to_euler(EulerRot::ZYX);
    [z, y, x]
}

/// The 16 cells of one body in one frame of a QTM 6D export.
pub(super) fn qualisys_cells(t: &OutTrack, f: usize) -> Vec<String> {
    let (Some(p), Some(q)) = (t.positions[f], t.rotations[f]) else {
        return vec!["NaN".to_string(); 16];
    };
    let mut cells: Vec<String> = (p * 1000.0).to_array().map(|v| num(v, 5)).into();
    cells.extend(qualisys_angles_deg(q).map(|v| num(v, 5)));
    cells.push(num(fit_error_m(f, t.body) * 4000.0, 5));
    cells.extend(DMat3::from_quat(q).to_cols_array().map(|v| num(v, 5)));
    cells
}

/// Qualisys QTM 6D TSV (see the module doc).
pub(super) fn qualisys(out: &OutTake) -> String {
    let bodies: Vec<&OutTrack> = out.tracks.iter().filter(|t| t.kind == Kind::Body).collect();
    let names: Vec<&str> = bodies.iter().map(|t| t.label.as_str()).collect();
    let mut s = String::new();
    for (key, value) in [
        ("NO_OF_FRAMES", out.rows.len().to_string()),
        ("NO_OF_CAMERAS", "12".into()),
        ("NO_OF_BODIES", bodies.len().to_string()),
        ("FREQUENCY", rate_text(out.rate_hz)),
        ("NO_OF_ANALOG", "0".into()),
        ("ANALOG_FREQUENCY", "0".into()),
        ("DESCRIPTION", "--".into()),
        ("TIME_STAMP", "2026-11-30, 10:21:07\t4711.08154296".into()),
        ("DATA_INCLUDED", "6D".into()),
        ("BODY_NAMES", names.join("\t")),
    ] {
        let _ = writeln!(s, "{key}\t{value}");
    }
    s += "Frame\tTime\t";
    for name in &names {
        let _ = write!(s, "{name} X\tY\tZ\tRoll\tPitch\tYaw\tResidual\t");
        for k in 0..9 {
            let _ = write!(s, "Rot[{k}]\t");
        }
    }
    s.push('\n');
    for &f in &out.rows {
        let _ = write!(s, "{}\t{:.5}\t", f + 1, f as f64 / out.rate_hz);
        for b in &bodies {
            for c in qualisys_cells(b, f) {
                s += &c;
                s.push('\t');
            }
        }
        s.push('\n');
    }
    s
}

/// OpenSim TRC (see the module doc).
pub(super) fn trc(out: &OutTake, style: &LabStyle) -> String {
    let unit = style.written_unit();
    let n = out.tracks.len();
    let r = out.rate_hz;
    let mut s = format!(
        "PathFileType\t4\t(X/Y/Z)\t{}.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\t\
         OrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n{r:.2}\t{r:.2}\t{}\t{n}\t{}\t{r:.2}\t1\t{}\n",
        out.name,
        out.rows.len(),
        unit.symbol(),
        out.frames
    );
    let labels: Vec<String> = out
        .tracks
        .iter()
        .map(|t| format!("{}\t\t", t.label))
        .collect();
    let _ = writeln!(
        s,
        "Frame#\tTime\t{}",
        labels.join("\t").trim_end_matches('\t')
    );
    let axes: Vec<String> = (1..=n).map(|i| format!("X{i}\tY{i}\tZ{i}")).collect();
    let _ = writeln!(s, "\t\t{}\n", axes.join("\t"));
    let (scale, d) = (1.0 / unit.metres(), decimals(Layout::Trc, unit));
    for &f in &out.rows {
        let cells = marker_cells(out, f, scale, d).join("\t");
        let _ = writeln!(s, "{}\t{:.5}\t{cells}", f + 1, f as f64 / r);
    }
    s
}

/// `v`'s text with a decimal comma.
pub(super) fn comma(v: String) -> String {
    v.replace('.', ",")
}

/// The vendor CSV (see the module doc).
pub(super) fn vendor(out: &OutTake, style: &LabStyle) -> String {
    let unit = style.written_unit();
    let mode = out
        .labels
        .mode
        .map_or("stroke".into(), |m| m.name().to_string());
    let title = style
        .title
        .clone()
        .unwrap_or_else(|| format!("Take \"Session 3 – {mode}\" exported 2026-11-30 10:21"));
    let mut s = format!(
        "{title}\nCapture rate (Hz);{}\nUnits;{}\n\nFrame",
        comma(rate_text(out.rate_hz)),
        unit.symbol()
    );
    let bodies: Vec<&OutTrack> = out.tracks.iter().filter(|t| t.kind == Kind::Body).collect();
    for b in &bodies {
        for part in ["Pos X", "Pos Y", "Pos Z", "Rot Z", "Rot Y", "Rot X"] {
            let _ = write!(s, ";{} {part}", b.label);
        }
    }
    s.push('\n');
    let (scale, d) = (1.0 / unit.metres(), decimals(Layout::Vendor, unit));
    for &f in &out.rows {
        let _ = write!(s, "{}", f + 1);
        for b in &bodies {
            let angles = b.rotations[f].map(|q| vendor_angles_rad(q).map(|v| num(v, 5)));
            let cells = xyz_cells(b.positions[f], scale, d)
                .into_iter()
                .chain(angles.unwrap_or_default());
            for c in cells {
                let _ = write!(s, ";{}", comma(c));
            }
        }
        s.push('\n');
    }
    s
}
