//! Statistics every scene's aggregation shares: mean, standard deviation and standard error,
//! least-squares slopes of cumulative series with an honest standard error (seed paper
//! section 4, Figs. 8 and 10), and the error that names a field of data that cannot be
//! aggregated.

use serde::{Deserialize, Serialize};

/// Data that cannot be aggregated; names the field (`cells[1].samples[3].impacts[7]...`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AggregateError {
    /// A field breaks a rule.
    #[error("{field}: {rule}")]
    Invalid {
        /// Path of the offending field.
        field: String,
        /// The rule broken, in words.
        rule: String,
    },
}

impl AggregateError {
    /// The same error with its field inside `prefix` (`cells[2].…`).
    pub fn within(self, prefix: &str) -> Self {
        match self {
            AggregateError::Invalid { field, rule } => AggregateError::Invalid {
                field: format!("{prefix}.{field}"),
                rule,
            },
        }
    }
}

/// An [`AggregateError::Invalid`] naming `field`.
pub fn invalid(field: String, rule: impl Into<String>) -> AggregateError {
    AggregateError::Invalid {
        field,
        rule: rule.into(),
    }
}

/// Ordinary least-squares slope of y on x; `None` for fewer than 2 points or constant x.
pub fn least_squares_slope(x: &[f64], y: &[f64]) -> Option<f64> {
    assert_eq!(
        x.len(),
        y.len(),
        "least_squares_slope: x and y differ in length"
    );
    let n = x.len();
    if n < 2 {
        return None;
    }
    let c = CentredSums::of(x, y);
    (c.sxx > 0.0).then(|| c.sxy / c.sxx)
}

/// The sums of a least-squares line about the means: x̄, Σ(x − x̄)(y − ȳ) and Σ(x − x̄)².
pub(crate) struct CentredSums {
    pub xm: f64,
    pub sxy: f64,
    pub sxx: f64,
}

impl CentredSums {
    /// Over the first min(len) points of x and y (at least one).
    pub(crate) fn of(x: &[f64], y: &[f64]) -> CentredSums {
        let n = x.len().min(y.len());
        let (x, y) = (&x[..n], &y[..n]);
        let xm = x.iter().sum::<f64>() / n as f64;
        let ym = y.iter().sum::<f64>() / n as f64;
        // Centred sums: cumulative masses are large offsets with small increments, and the
        // uncentred formula would cancel catastrophically.
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (xi, yi) in x.iter().zip(y) {
            sxy += (xi - xm) * (yi - ym);
            sxx += (xi - xm) * (xi - xm);
        }
        CentredSums { xm, sxy, sxx }
    }
}

/// Mean, sample standard deviation (n − 1) and standard error of the mean.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1); `None` below 2 values.
    pub std: Option<f64>,
    /// Standard error of the mean, std/√n; `None` below 2 values.
    pub sem: Option<f64>,
}

/// Mean, sample std (n − 1) and standard error of `values`; `None` when empty.
pub fn stats(values: &[f64]) -> Option<Stats> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let std = (n >= 2).then(|| {
        let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
        (ss / (n - 1) as f64).sqrt()
    });
    Some(Stats {
        mean,
        std,
        sem: std.map(|s| s / (n as f64).sqrt()),
    })
}

/// A least-squares slope with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlopeFit {
    /// Slope of cumulative mass loss against cumulative grain mass (dimensionless).
    pub value: f64,
    /// Standard error of the slope under independent per-impact losses.
    pub sem: f64,
}

/// Least-squares slope of y on x with its standard error for a cumulative series whose
/// increments are independent: `None` below 3 points or for constant x.
///
/// With the increments `Δyⱼ = b·Δxⱼ + εⱼ`, εⱼ independent with variance σ², the slope is
/// `b = Σⱼ wⱼ Δyⱼ` with `wⱼ = Σ_{k≥j} (x_k − x̄) / Sxx`, so `Var b = σ² Σⱼ wⱼ²`; σ² is
/// estimated from the increments' residuals `Δyⱼ − b·Δxⱼ` with n − 2 degrees of freedom
/// (n − 1 increments, one slope).
pub fn slope_fit(x: &[f64], y: &[f64]) -> Option<SlopeFit> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let (x, y) = (&x[..n], &y[..n]);
    let CentredSums { xm, sxy, sxx } = CentredSums::of(x, y);
    if sxx <= 0.0 {
        return None;
    }
    let b = sxy / sxx;
    // Tail sums of centred x, from the last point back: w_j for j = n-1 down to 1.
    let (mut tail, mut sum_w2, mut ssr) = (0.0, 0.0, 0.0);
    for j in (1..n).rev() {
        tail += x[j] - xm;
        let w = tail / sxx;
        sum_w2 += w * w;
        let u = (y[j] - y[j - 1]) - b * (x[j] - x[j - 1]);
        ssr += u * u;
    }
    let sigma2 = ssr / (n - 2) as f64;
    Some(SlopeFit {
        value: b,
        sem: (sigma2 * sum_w2).sqrt(),
    })
}
