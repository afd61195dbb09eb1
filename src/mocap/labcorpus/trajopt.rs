//! The real TrajOptDrums stroke (Pearl 2023, MIT) repeated into a take of several strokes
//! with known impacts.

use super::*;

/// The real stroke: each marker's forward and vertical position per frame, m.
pub(super) struct RealStroke {
    pub(super) rate_hz: f64,
    /// Marker names without " Joint" (the bead excluded).
    pub(super) names: Vec<String>,
    /// Forward (x) and up (y) per marker, bead last, per frame.
    pub(super) forward: Vec<Vec<f64>>,
    pub(super) up: Vec<Vec<f64>>,
    /// Time of the bead's minimum on the interpolant, s.
    pub(super) impact_s: f64,
    /// Nominal period (from the file's "…bpm" cell, else 100 bpm), s.
    pub(super) period_s: f64,
}

/// One of the two TrajOptDrums files.
pub(super) struct PoseFile {
    pub(super) names: Vec<String>,
    pub(super) times: Vec<f64>,
    /// Per column, per frame, m.
    pub(super) values: Vec<Vec<f64>>,
    pub(super) bpm: Option<f64>,
}

/// The bead's column name.
pub(super) const BEAD: &str = "Drum Bead";

impl PoseFile {
    /// Parse `Time (s),Shoulder Joint,…,Drum Bead,(cm),100bpm` and numeric rows.
    pub(super) fn parse(text: &str, file: &str) -> Result<PoseFile, CorpusError> {
        let err = |place: String, message: String| CorpusError::Source {
            file: file.to_string(),
            place,
            message,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| err("line 1".into(), "expected a header, found nothing".into()))?;
        let cells: Vec<&str> = header.split(',').map(str::trim).collect();
        if !cells[0].starts_with("Time") {
            return Err(err(
                "line 1".into(),
                format!("expected \"Time (s)\" first, found \"{}\"", cells[0]),
            ));
        }
        let unit_m = if cells.iter().any(|c| c.contains("mm")) {
            0.001
        } else {
            0.01
        };
        let bpm = cells
            .iter()
            .find_map(|c| c.strip_suffix("bpm").and_then(|n| n.trim().parse().ok()));
        let columns: Vec<usize> = (1..cells.len())
            .filter(|&c| {
                let s = cells[c];
                !s.is_empty() && !s.ends_with("bpm") && !s.contains("cm") && !s.contains("mm")
            })
            .collect();
        let mut times = Vec::new();
        let mut values = vec![Vec::new(); columns.len()];
        for (i, line) in lines {
            let row: Vec<&str> = line.split(',').map(str::trim).collect();
            let number = |c: usize| {
                row.get(c)
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        err(
                            format!("line {}, column {}", i + 1, c + 1),
                            "expected a number".into(),
                        )
                    })
            };
            times.push(number(0)?);
            for (v, &c) in values.iter_mut().zip(&columns) {
                v.push(number(c)? * unit_m);
            }
        }
        if times.len() < 8 {
            return Err(err(
                "data".into(),
                format!(
                    "expected a stroke of at least 8 frames, found {}",
                    times.len()
                ),
            ));
        }
        Ok(PoseFile {
            names: columns.iter().map(|&c| cells[c].to_string()).collect(),
            times,
            values,
            bpm,
        })
    }

    pub(super) fn column(&self, name: &str) -> Option<&Vec<f64>> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| &self.values[i])
    }
}

/// Catmull-Rom interpolation of uniform samples at fractional index `s` (held beyond
/// the ends).
pub(super) fn catmull_rom(v: &[f64], s: f64) -> f64 {
    let last = v.len() - 1;
    if s <= 0.0 {
        return v[0];
    }
    if s >= last as f64 {
        return v[last];
    }
    let i = (s.floor() as usize).min(last - 1);
    let u = s - i as f64;
    let p = |k: isize| v[(i as isize + k).clamp(0, last as isize) as usize];
    let (p0, p1, p2, p3) = (p(-1), p(0), p(1), p(2));
    0.5 * (2.0 * p1
        + (p2 - p0) * u
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * u * u * u)
}

/// Start of the cross-fade from the rebound into the next lift, s after the impact.
pub(super) const BLEND_START_S: f64 = 0.0125;
/// End of the cross-fade, s after the impact (at most the recorded rebound's length).
pub(super) const BLEND_END_S: f64 = 0.0375;
/// The take starts this long after the virtual impact before the first, s.
pub(super) const LEAD_IN_S: f64 = 0.05;

impl RealStroke {
    /// Read both files: the X pose gives the forward, the Y pose the vertical positions.
    pub(super) fn parse(x_csv: &str, y_csv: &str) -> Result<RealStroke, CorpusError> {
        let x = PoseFile::parse(x_csv, "JointCenters_XPose_cm.csv")?;
        let y = PoseFile::parse(y_csv, "JointCenters_YPose_cm.csv")?;
        let bad = |message: String| CorpusError::Source {
            file: "JointCenters_YPose_cm.csv".into(),
            place: "whole file".into(),
            message,
        };
        if x.times.len() != y.times.len() || x.names != y.names {
            return Err(bad(
                "expected the same columns and frames as the X pose file".into(),
            ));
        }
        let n = x.times.len();
        let step = (x.times[n - 1] - x.times[0]) / (n - 1) as f64;
        if !step.is_finite() || step <= 0.0 {
            return Err(bad("expected rising times".into()));
        }
        let mut names: Vec<String> = x.names.iter().filter(|n| *n != BEAD).cloned().collect();
        names.push(BEAD.into());
        let pick = |f: &PoseFile| -> Result<Vec<Vec<f64>>, CorpusError> {
            names
                .iter()
                .map(|name| {
                    f.column(name)
                        .cloned()
                        .ok_or_else(|| bad(format!("expected a \"{name}\" column")))
                })
                .collect()
        };
        let (forward, up) = (pick(&x)?, pick(&y)?);
        names.pop();
        let mut stroke = RealStroke {
            rate_hz: 1.0 / step,
            names: names
                .iter()
                .map(|n| n.trim_end_matches(" Joint").to_string())
                .collect(),
            forward,
            up,
            impact_s: 0.0,
            period_s: 60.0 / y.bpm.or(x.bpm).unwrap_or(100.0),
        };
        stroke.impact_s = stroke.bead_minimum_s();
        if stroke.impact_s + BLEND_END_S > (n - 1) as f64 * step {
            return Err(bad(
                "expected the recording to go on at least 37.5 ms after the bead's lowest \
                 point (the rebound)"
                    .into(),
            ));
        }
        Ok(stroke)
    }

    pub(super) fn bead(&self) -> usize {
        self.up.len() - 1
    }

    /// Marker `m`'s (forward, up) at time `t` of the recording, m.
    pub(super) fn at(&self, m: usize, t: f64) -> (f64, f64) {
        let s = t * self.rate_hz;
        (
            catmull_rom(&self.forward[m], s),
            catmull_rom(&self.up[m], s),
        )
    }

    /// The time of the bead's lowest point on the interpolant (golden-section search
    /// around the lowest sample), s.
    pub(super) fn bead_minimum_s(&self) -> f64 {
        let up = &self.up[self.bead()];
        let i = (0..up.len())
            .min_by(|&a, &b| up[a].total_cmp(&up[b]))
            .expect("a stroke has frames");
        let height = |t: f64| catmull_rom(up, t * self.rate_hz);
        let (mut lo, mut hi) = (
            (i as f64 - 1.0).max(0.0) / self.rate_hz,
            (i as f64 + 1.0) / self.rate_hz,
        );
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..80 {
            let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if height(a) < height(b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        0.5 * (lo + hi)
    }

    /// Marker `m` of the stitched take at time `t` (s after the file starts): forward
    /// and up relative to the bead at the impact, m.
    pub(super) fn stitched(&self, plan: &StrokePlan, m: usize, t: f64) -> (f64, f64) {
        let k = plan
            .impacts_s
            .iter()
            .position(|&ti| ti > t)
            .unwrap_or(plan.impacts_s.len() - 1)
            .max(1);
        let (t0, t1) = (plan.impacts_s[k - 1], plan.impacts_s[k]);
        let tau = t - t0;
        let pace = self.period_s / (t1 - t0);
        let (x0, y0) = self.at(self.bead(), self.impact_s);
        let scaled = |(x, y): (f64, f64), h: f64| (x - x0, (y - y0) * h);
        let rebound = scaled(self.at(m, self.impact_s + tau), plan.heights[k - 1]);
        let lift = scaled(
            self.at(m, self.impact_s - (t1 - t0 - tau) * pace),
            plan.heights[k],
        );
        let w = smoothstep((tau - BLEND_START_S) / (BLEND_END_S - BLEND_START_S));
        (
            rebound.0 + (lift.0 - rebound.0) * w,
            rebound.1 + (lift.1 - rebound.1) * w,
        )
    }

    /// The take: `strokes` impacts at the nominal period with seeded tempo and height
    /// variation, sampled at `rate_hz`, at the right hand's nearest drum.
    pub(super) fn take(&self, strokes: usize, rate_hz: f64, rng: &mut Rng) -> PerformerTake {
        let plan = StrokePlan::new(strokes, self.period_s, rng);
        let end_s = plan.impacts_s[strokes] + 0.5 * self.period_s;
        let frames = (end_s * rate_hz).floor() as usize + 1;
        let shoulder = Skeleton::default().shoulder(Side::Right);
        let (drum, drum_name) = nearest_drum(shoulder, Some(Side::Right));
        let spot =
            Kit::standard().drums[drum].point_on_head(ImpactLocation::PLAYING_SPOT_RADIUS, 0.0);
        let ahead = (spot - shoulder).truncate().normalize().extend(0.0);
        let place = |m: usize, t: f64| {
            let (x, y) = self.stitched(&plan, m, t);
            spot + ahead * x + DVec3::Z * y
        };
        let track = |m: usize| -> Vec<DVec3> {
            (0..frames).map(|f| place(m, f as f64 / rate_hz)).collect()
        };
        let tip = track(self.bead());
        let finger = self.names.iter().position(|n| n == "Finger");
        let stick = match finger {
            Some(f) => track(f)
                .iter()
                .zip(&tip)
                .map(|(a, b)| stick_frame(*b - *a, ahead))
                .collect(),
            None => vec![stick_frame(-DVec3::Z, ahead); frames],
        };
        let markers = (0..self.names.len())
            .map(|m| (self.names[m].clone(), track(m)))
            .collect();
        PerformerTake {
            name: format!("trajoptdrums-{strokes}-strokes"),
            rate_hz,
            sides: vec![SideSamples {
                side: Side::Right,
                tip,
                stick,
                markers,
                impacts: plan.impacts_s[1..=strokes]
                    .iter()
                    .map(|&time_s| Impact {
                        time_s,
                        dynamic: None,
                    })
                    .collect(),
            }],
            labels: SourceLabels {
                source: "TrajOptDrums (Pearl 2023, MIT): one real stroke at 240 Hz, repeated"
                    .into(),
                drum,
                drum_name,
                location: Some(ImpactLocation::PlayingSpot),
                mode: None,
                grip: None,
            },
        }
    }
}

/// The stick frame for a stick pointing along `along` (grip to tip) in the vertical
/// plane through `ahead`: −Z along the stick, X normal to the plane (to the right).
pub(super) fn stick_frame(along: DVec3, ahead: DVec3) -> DQuat {
    let z = -along.normalize();
    let x = ahead.cross(DVec3::Z).normalize();
    let x = (x - z * x.dot(z)).normalize();
    DQuat::from_mat3(&DMat3::from_cols(x, z.cross(x), z))
}

pub(super) fn smoothstep(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// Impact times (a virtual one before and after the real ones) and each stroke's height
/// factor.
pub(super) struct StrokePlan {
    /// T_0 … T_{N+1}, s after the file starts.
    pub(super) impacts_s: Vec<f64>,
    /// Height factor of the stroke ending at each impact.
    pub(super) heights: Vec<f64>,
}

impl StrokePlan {
    pub(super) fn new(strokes: usize, period_s: f64, rng: &mut Rng) -> StrokePlan {
        let mut impacts_s = vec![-LEAD_IN_S];
        let mut heights = vec![1.0];
        for _ in 0..=strokes {
            let pace = 1.0 + 0.02 * rng.normal().clamp(-2.5, 2.5);
            impacts_s.push(impacts_s[impacts_s.len() - 1] + period_s * pace);
            heights.push(1.0 + 0.04 * rng.normal().clamp(-2.5, 2.5));
        }
        StrokePlan { impacts_s, heights }
    }
}
