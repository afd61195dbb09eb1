//! Small statistics shared by the layers that measure data: the median (the upper
//! middle value) of the finite values of a set, and the least-squares line through
//! points.

/// The median of the finite values of `values`: the middle one of an odd count, the upper
/// of the two middle ones of an even count; `None` when there is no finite value.
pub fn median(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// A least-squares line y = mean_y + slope·(x − mean_x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub mean_x: f64,
    pub mean_y: f64,
    pub slope: f64,
}

impl Line {
    /// The line's y at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.mean_y + self.slope * (x - self.mean_x)
    }
}

/// The least-squares line through `points` (x, y); its slope is not finite when every x
/// is the same (or there is no point).
pub fn least_squares_line(points: &[(f64, f64)]) -> Line {
    let n = points.len() as f64;
    let (mean_x, mean_y) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (
            a + (p.0 - mean_x) * (p.1 - mean_y),
            b + (p.0 - mean_x) * (p.0 - mean_x),
        )
    });
    Line {
        mean_x,
        mean_y,
        slope: sxy / sxx,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_through_points() {
        let line = least_squares_line(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]);
        assert_eq!((line.mean_x, line.mean_y, line.slope), (1.0, 3.0, 2.0));
        assert_eq!(line.at(4.0), 9.0);
        // Scattered about y = x: the slope of the fit, not of any pair.
        let line = least_squares_line(&[(0.0, 0.5), (1.0, 0.5), (2.0, 2.5), (3.0, 2.5)]);
        assert!((line.slope - 0.8).abs() < 1e-12, "{line:?}");
        assert!(
            !least_squares_line(&[(1.0, 0.0), (1.0, 2.0)])
                .slope
                .is_finite()
        );
    }

    #[test]
    fn upper_median_of_the_finite_values() {
        assert_eq!(median([3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median([4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median([f64::NAN, 5.0, f64::INFINITY]), Some(5.0));
        assert_eq!(median([f64::NAN]), None);
        assert_eq!(median(Vec::new()), None);
    }
}
