//! Keeping plots cheap: the points of a long series inside a visible x window reduced to
//! a bounded count by min/max decimation (each of equal x buckets keeps its lowest and its
//! highest point, so peaks survive), and an audio envelope (min/max of the channel mean
//! per time bucket, from per-block extremes when a bucket spans many blocks). Pure math,
//! no egui.

use crate::base::chunks::SharedChunks;

/// The points of `points` (sorted by x) that draw the window `x0..=x1`: those inside it
/// plus one neighbour on each side, so a line reaches the edges.
pub fn visible(points: &[[f64; 2]], x0: f64, x1: f64) -> &[[f64; 2]] {
    let first = points.partition_point(|p| p[0] < x0).saturating_sub(1);
    let last = (points.partition_point(|p| p[0] <= x1) + 1).min(points.len());
    &points[first..last.max(first)]
}

/// `points` (sorted by x) reduced to at most `max_points` (≥ 4) by M4 decimation: the x
/// range is cut into `max_points / 4` equal buckets and each keeps its first, lowest,
/// highest and last point, in x order — peaks survive, and so does a line's return to a
/// level between sparse pulses. Series no longer than `max_points` are returned whole.
pub fn min_max(points: &[[f64; 2]], max_points: usize) -> Vec<[f64; 2]> {
    let max_points = max_points.max(4);
    if points.len() <= max_points {
        return points.to_vec();
    }
    let buckets = max_points / 4;
    let (x0, x1) = (points[0][0], points[points.len() - 1][0]);
    let width = (x1 - x0) / buckets as f64;
    let bucket_of = |x: f64| {
        if width > 0.0 {
            (((x - x0) / width) as usize).min(buckets - 1)
        } else {
            0
        }
    };
    let mut out = Vec::with_capacity(max_points);
    let mut flush = |first: usize, lo: usize, hi: usize, last: usize| {
        let mut keep = [first, lo, hi, last];
        keep.sort_unstable();
        let mut previous = None;
        for i in keep {
            if previous != Some(i) {
                out.push(points[i]);
                previous = Some(i);
            }
        }
    };
    let (mut bucket, mut first, mut lo, mut hi) = (bucket_of(x0), 0, 0, 0);
    for (i, p) in points.iter().enumerate().skip(1) {
        let b = bucket_of(p[0]);
        if b != bucket {
            flush(first, lo, hi, i - 1);
            (bucket, first, lo, hi) = (b, i, i, i);
        } else if p[1] < points[lo][1] {
            lo = i;
        } else if p[1] > points[hi][1] {
            hi = i;
        }
    }
    flush(first, lo, hi, points.len() - 1);
    out
}

/// Interleaved audio summarised for drawing: the min and max of the channel mean over
/// blocks of [`Envelope::BLOCK`] frames, computed once per rendering.
#[derive(Clone, Debug, Default)]
pub struct Envelope {
    rate_hz: f64,
    channels: usize,
    frames: usize,
    /// [min, max] of each block.
    blocks: Vec<[f32; 2]>,
}

/// One bucket of an envelope: its time span (s) and the extremes of the signal in it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bucket {
    pub t0_s: f64,
    pub t1_s: f64,
    pub min: f32,
    pub max: f32,
}

impl Envelope {
    /// Frames per block.
    pub const BLOCK: usize = 256;

    /// The block extremes of `samples` (`channels` interleaved, `rate_hz` frames per second,
    /// frame 0 at time 0).
    pub fn new(samples: &SharedChunks<f32>, channels: usize, rate_hz: f64) -> Envelope {
        let channels = channels.max(1);
        let per_block = Self::BLOCK * channels;
        let blocks = (0..samples.len())
            .step_by(per_block)
            .map(|a| {
                let z = (a + per_block).min(samples.len());
                extremes(&samples.to_vec_of(a..z), channels)
            })
            .collect();
        Envelope {
            rate_hz,
            channels,
            frames: samples.len() / channels,
            blocks,
        }
    }

    /// The envelope of `samples` (the same ones given to [`Envelope::new`]) over
    /// `t0..t1` s in `buckets` equal buckets: exact from the samples when a bucket holds
    /// fewer than four blocks, else from whole blocks (a bucket's edges then move by under
    /// a block, ≈ 5 ms at 48 kHz). Buckets outside the audio are left out.
    pub fn buckets(
        &self,
        samples: &SharedChunks<f32>,
        t0: f64,
        t1: f64,
        buckets: usize,
    ) -> Vec<Bucket> {
        if buckets == 0 || t1 <= t0 || self.frames == 0 {
            return Vec::new();
        }
        let frame_at = |t: f64| ((t * self.rate_hz).round().max(0.0) as usize).min(self.frames);
        let per_bucket = (t1 - t0) * self.rate_hz / buckets as f64;
        let coarse = per_bucket >= 4.0 * Self::BLOCK as f64;
        (0..buckets)
            .filter_map(|b| {
                let a = t0 + (t1 - t0) * b as f64 / buckets as f64;
                let z = t0 + (t1 - t0) * (b + 1) as f64 / buckets as f64;
                let (fa, fz) = (
                    frame_at(a),
                    frame_at(z).max(frame_at(a) + 1).min(self.frames),
                );
                if fa >= fz {
                    return None;
                }
                let [min, max] = if coarse {
                    let (ba, bz) = (fa / Self::BLOCK, fz.div_ceil(Self::BLOCK));
                    self.blocks[ba..bz.min(self.blocks.len())]
                        .iter()
                        .fold([f32::INFINITY, f32::NEG_INFINITY], |m, x| {
                            [m[0].min(x[0]), m[1].max(x[1])]
                        })
                } else {
                    extremes(
                        &samples.to_vec_of(fa * self.channels..fz * self.channels),
                        self.channels,
                    )
                };
                Some(Bucket {
                    t0_s: a,
                    t1_s: z,
                    min,
                    max,
                })
            })
            .collect()
    }
}

/// [min, max] of the channel mean of interleaved `samples`.
fn extremes(samples: &[f32], channels: usize) -> [f32; 2] {
    samples
        .chunks_exact(channels)
        .map(|f| f.iter().sum::<f32>() / channels as f32)
        .fold([f32::INFINITY, f32::NEG_INFINITY], |m, x| {
            [m[0].min(x), m[1].max(x)]
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decimation caps the count, keeps x order, keeps every bucket's extremes (so the
    /// global peak and trough survive) and returns short series unchanged.
    #[test]
    fn min_max_keeps_extremes_under_the_cap() {
        let points: Vec<[f64; 2]> = (0..15_000)
            .map(|k| {
                let t = k as f64 / 250.0;
                [t, (t * 7.0).sin() + if k == 7_321 { 5.0 } else { 0.0 }]
            })
            .collect();
        let d = min_max(&points, 2000);
        assert!(d.len() <= 2000 && d.len() > 1000, "{}", d.len());
        assert!(d.windows(2).all(|w| w[0][0] < w[1][0]));
        assert!(d.contains(&points[7_321]), "the spike survives");
        let low = points.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        assert!(d.iter().any(|p| p[1] == low));
        // Every bucket's extremes are kept: the decimated max and min over any bucket
        // equal the true ones.
        let width = points[14_999][0] / 500.0;
        for b in [0, 17, 250, 499] {
            let inside = |p: &&[f64; 2]| ((p[0] / width) as usize).min(499) == b;
            let extremes = |v: &[[f64; 2]]| {
                v.iter().filter(inside).fold([f64::MAX, f64::MIN], |m, p| {
                    [m[0].min(p[1]), m[1].max(p[1])]
                })
            };
            assert_eq!(extremes(&points), extremes(&d), "bucket {b}");
        }
        let short = &points[..100];
        assert_eq!(min_max(short, 2000), short.to_vec());
    }

    /// Sparse pulses on a zero line keep their returns to zero (a bucket's first and last
    /// points), so no line is drawn from one pulse's peak down to the next pulse.
    #[test]
    fn min_max_keeps_pulse_edges() {
        // 100 pulses of 1 ms, each in the middle of one of the 100 buckets of 0.2 s.
        let mut points = vec![[0.0, 0.0]];
        for pulse in 0..100 {
            let t = 0.1 + 0.2 * f64::from(pulse);
            for k in 0..10 {
                let x = f64::from(k) / 9.0;
                let force = if k == 0 || k == 9 {
                    0.0
                } else {
                    50.0 * (1.0 - (2.0 * x - 1.0).abs()) + 1.0
                };
                points.push([t - 5e-4 + 1e-3 * x, force]);
            }
        }
        points.push([20.0, 0.0]);
        let d = min_max(&points, 400);
        assert!(d.len() <= 400);
        // Between pulses the line lies at zero: every segment from one bucket to the next
        // is flat at 0 (inside a bucket, about a pixel wide, the order of points is kept).
        let bucket = |x: f64| ((x / 0.2) as usize).min(99);
        for w in d.windows(2) {
            if bucket(w[0][0]) != bucket(w[1][0]) {
                assert_eq!((w[0][1], w[1][1]), (0.0, 0.0), "{w:?}");
            }
        }
        let top = |v: &[[f64; 2]]| v.iter().filter(|p| p[1] > 40.0).count();
        assert_eq!(top(&d), 100, "every pulse keeps its peak");
    }

    /// The visible part of a series is the window plus one point each side, clamped.
    #[test]
    fn visible_window() {
        let points: Vec<[f64; 2]> = (0..10).map(|k| [k as f64, 0.0]).collect();
        let v = visible(&points, 2.5, 5.0);
        assert_eq!((v[0][0], v[v.len() - 1][0]), (2.0, 6.0));
        assert_eq!(visible(&points, -5.0, 100.0).len(), 10);
        assert_eq!(
            visible(&points, 20.0, 30.0).len(),
            1,
            "only the last, as a neighbour"
        );
        assert!(visible(&[], 0.0, 1.0).is_empty());
    }

    /// The envelope of a stereo sine matches the true extremes of the channel mean, by
    /// blocks and exactly, and leaves out buckets past the end.
    #[test]
    fn envelope_of_a_sine() {
        let rate = 48_000.0;
        let frames = 48_000 * 2;
        let mut samples = Vec::with_capacity(2 * frames);
        for k in 0..frames {
            let t = k as f64 / rate;
            // Left and right differ; their mean swells from 0 to 0.5 over the two seconds.
            let v = 0.25 * t * (std::f64::consts::TAU * 440.0 * t).sin();
            samples.extend([(v + 0.1) as f32, (v - 0.1) as f32]);
        }
        let chunked = SharedChunks::from_vec(samples.clone(), 1000);
        let env = Envelope::new(&chunked, 2, rate);
        // Coarse: 20 buckets of 0.1 s (≈ 19 blocks each).
        let coarse = env.buckets(&chunked, 0.0, 2.0, 20);
        assert_eq!(coarse.len(), 20);
        for b in &coarse {
            let peak = (0.25 * b.t1_s) as f32;
            assert!((b.max - peak).abs() < 0.01, "{b:?}");
            assert!((b.min + peak).abs() < 0.01, "{b:?}");
        }
        // Fine: exact extremes of a 10 ms window.
        let fine = env.buckets(&chunked, 1.0, 1.01, 2);
        let exact = |a: usize, z: usize| extremes(&samples[2 * a..2 * z], 2);
        assert_eq!([fine[0].min, fine[0].max], exact(48_000, 48_240));
        assert_eq!([fine[1].min, fine[1].max], exact(48_240, 48_480));
        // Past the end: nothing.
        assert_eq!(env.buckets(&chunked, 1.5, 3.0, 3).len(), 1);
        assert!(env.buckets(&chunked, 1.0, 1.0, 3).is_empty());
    }
}
