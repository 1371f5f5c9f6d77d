//! The damage balance of a cell: whether the mass its last window removed pays for the damage
//! its impacts added (`docs/erosion.md`, *The damage balance*; eq. 19 of the seed paper).
//!
//! A particle is removed when its Johnson–Cook damage D reaches 1, so every kilogram lost has
//! carried one kilogram of damage, and the surface's damage stock Σ m D changes by what the
//! impacts add less what the removed mass takes away. While the stock still grows, the loss
//! rate is a transient on its way up, whatever two adjacent slopes say: on the 16-per-Dg
//! rung the loss met the damage added only after about 350 impacts, with a rate 70 % above
//! the one three agreeing windows had passed at 240. Stationarity is the balance: loss and
//! damage added per gram of grain agree over the last window.
//!
//! Both rates are taken the same way in each sample, Σ loss (or Σ damage added) over Σ grain
//! mass of its last [`BALANCE_POINTS`] impacts, and compared in pairs: the sample's loss less
//! its damage added. The cell is balanced when the mean of those differences is within
//! [`BALANCE_SIGMAS`] standard errors of zero and the loss is at least [`BALANCE_MIN_RATIO`]
//! of the damage added. The floor gives the test its power where the loss is noisy: on 15
//! samples at 16 per Dg the loss's standard error is 15 % of its mean, and a window that removed
//! 22 % less than it damaged passed the difference test alone. A detached fragment leaves with
//! the damage it had, below 1, so a stationary surface loses a little more than it adds; the
//! test does not correct for that, and the ratio it reports shows it.

use serde::{Deserialize, Serialize};

use super::aggregate::{Impact, SampleInput, SLOPE_WINDOW};
use crate::stats::stats;

/// Impacts of the window over which loss and damage added are compared: the paper's last-20
/// erosion window (section 4).
pub const BALANCE_POINTS: usize = SLOPE_WINDOW;

/// Impacts of the long window reported beside the last one ([`assess_long`]): three balance
/// windows. The stopping rule ends a cell on the first window that passes, which is most often
/// one that fluctuated up; over the last 60 impacts the loss of the seed's campaign's 45° cell
/// was 6 % below its last window's (docs/results.md, *At the damage balance*).
pub const LONG_BALANCE_POINTS: usize = 3 * BALANCE_POINTS;

/// Largest mean difference of loss and damage added per gram, in standard errors of that
/// mean, that still counts as a balance (about a 95 % two-sided test).
pub const BALANCE_SIGMAS: f64 = 2.0;

/// Smallest loss / damage added that counts as a balance: the stationary rate lies between the
/// two, so the loss is then within 10 % of it, the tolerance the resolution ladder is judged by
/// (`docs/erosion.md`, *The damage balance*).
pub const BALANCE_MIN_RATIO: f64 = 0.9;

/// Loss against damage added over a cell's last window (seed paper eq. 19: a particle leaves
/// at D = 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DamageBalance {
    /// Impacts of each sample's window.
    pub points: usize,
    /// Samples compared: those with a full window.
    pub samples: usize,
    /// Mean over samples of Σ loss / Σ grain mass over the window (dimensionless).
    pub loss_rate: f64,
    /// Standard error of `loss_rate`.
    pub loss_rate_sem: f64,
    /// Mean over samples of Σ damage added / Σ grain mass over the window (dimensionless).
    pub damage_rate: f64,
    /// Standard error of `damage_rate`.
    pub damage_rate_sem: f64,
    /// Standard error of the mean paired difference `loss_rate − damage_rate`.
    pub difference_sem: f64,
    /// `loss_rate / damage_rate`: below 1 while the damage stock still grows; `null` when
    /// no damage was added.
    pub ratio: Option<f64>,
    /// Whether the difference is within [`BALANCE_SIGMAS`] of its standard error and `ratio`
    /// is at least [`BALANCE_MIN_RATIO`].
    pub balanced: bool,
    /// Smallest imbalance the test sees: [`BALANCE_SIGMAS`] standard errors over
    /// `damage_rate`; `null` when no damage was added.
    pub detectable_rel: Option<f64>,
}

impl DamageBalance {
    /// The balance rule on these numbers: |loss − damage added| within [`BALANCE_SIGMAS`]
    /// standard errors of the difference and loss ≥ [`BALANCE_MIN_RATIO`] × damage added. A
    /// results file written under an earlier rule is judged by this one when read.
    pub fn holds(&self) -> bool {
        let rounding = 1e-9 * self.loss_rate.abs().max(self.damage_rate.abs());
        let within = (self.loss_rate - self.damage_rate).abs()
            <= BALANCE_SIGMAS * self.difference_sem + rounding;
        let ratio = (self.damage_rate > 0.0).then(|| self.loss_rate / self.damage_rate);
        within && ratio.is_none_or(|r| r >= BALANCE_MIN_RATIO)
    }

    /// The comparison in words, rates in mg/g.
    pub fn describe(&self) -> String {
        let z = if self.difference_sem > 0.0 {
            format!(
                "{:.1} standard errors",
                (self.loss_rate - self.damage_rate).abs() / self.difference_sem
            )
        } else {
            "no scatter".to_string()
        };
        format!(
            "the last {} impacts lost {:.2} ± {:.2} mg/g and added damage of {:.2} ± {:.2} mg/g \
             (ratio {}; {z})",
            self.points,
            1e3 * self.loss_rate,
            1e3 * self.loss_rate_sem,
            1e3 * self.damage_rate,
            1e3 * self.damage_rate_sem,
            self.ratio.map_or("–".to_string(), |r| format!("{r:.2}")),
        )
    }
}

/// The balance over the last [`BALANCE_POINTS`] impacts of every sample that has them; `None`
/// below two such samples or when any of their windows has an impact without its damage
/// recorded (records written before it was).
pub fn assess(samples: &[&SampleInput]) -> Option<DamageBalance> {
    over_last(samples, BALANCE_POINTS)
}

/// The same over the last [`LONG_BALANCE_POINTS`] impacts of every sample that has them: once
/// the cell is balanced, the loss there estimates its stationary rate without the selection of
/// the window that ended it. It reports; it decides nothing.
pub fn assess_long(samples: &[&SampleInput]) -> Option<DamageBalance> {
    over_last(samples, LONG_BALANCE_POINTS)
}

/// The balance over each sample's last `points` impacts, in the samples that have them.
fn over_last(samples: &[&SampleInput], points: usize) -> Option<DamageBalance> {
    balance_of(
        points,
        samples
            .iter()
            .filter(|s| s.impacts.len() >= points)
            .map(|s| &s.impacts[s.impacts.len() - points..]),
    )
}

/// The balance of one window of every sample, impacts `end − BALANCE_POINTS + 1 ..= end`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WindowBalance {
    /// Last impact of the window (1-based).
    pub end: usize,
    /// Loss against damage added over that window, in the samples that reached it.
    pub balance: DamageBalance,
}

/// How a cell approached its balance: the balance of each whole window, impacts 1–20, 21–40,
/// …, over the samples that reached its end. Windows with fewer than two such samples, or an
/// impact without its damage recorded, are left out.
pub fn history(samples: &[&SampleInput]) -> Vec<WindowBalance> {
    let longest = samples.iter().map(|s| s.impacts.len()).max().unwrap_or(0);
    (1..=longest / BALANCE_POINTS)
        .map(|k| k * BALANCE_POINTS)
        .filter_map(|end| {
            let windows = samples
                .iter()
                .filter(|s| s.impacts.len() >= end)
                .map(|s| &s.impacts[end - BALANCE_POINTS..end]);
            balance_of(BALANCE_POINTS, windows).map(|balance| WindowBalance { end, balance })
        })
        .collect()
}

/// Paired loss against damage added per gram of grain over one window of `points` impacts per
/// sample.
fn balance_of<'a>(
    points: usize,
    windows: impl Iterator<Item = &'a [Impact]>,
) -> Option<DamageBalance> {
    let mut loss = Vec::new();
    let mut damage = Vec::new();
    for window in windows {
        let grain: f64 = window.iter().map(|i| i.grain_mass_kg).sum();
        let added = window
            .iter()
            .map(|i| i.damage_added_kg)
            .sum::<Option<f64>>()?;
        loss.push(window.iter().map(|i| i.mass_loss_kg).sum::<f64>() / grain);
        damage.push(added / grain);
    }
    let difference: Vec<f64> = loss.iter().zip(&damage).map(|(l, d)| l - d).collect();
    let (l, d, diff) = (stats(&loss)?, stats(&damage)?, stats(&difference)?);
    let difference_sem = diff.sem?;
    let positive = |x: f64| (d.mean > 0.0).then_some(x / d.mean);
    let mut b = DamageBalance {
        points,
        samples: loss.len(),
        loss_rate: l.mean,
        loss_rate_sem: l.sem?,
        damage_rate: d.mean,
        damage_rate_sem: d.sem?,
        difference_sem,
        ratio: positive(l.mean),
        balanced: false,
        detectable_rel: positive(BALANCE_SIGMAS * difference_sem),
    };
    b.balanced = b.holds();
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` impacts of 1e-4 kg grains, each losing `loss` and adding `added` × the grain mass.
    fn sample(index: u32, n: usize, loss: f64, added: Option<f64>) -> SampleInput {
        SampleInput {
            sample: index,
            impacts: (0..n)
                .map(|_| Impact {
                    grain_mass_kg: 1e-4,
                    mass_loss_kg: loss * 1e-4,
                    damage_added_kg: added.map(|a| a * 1e-4),
                })
                .collect(),
        }
    }

    #[test]
    fn a_stock_still_growing_is_not_balanced_and_a_paid_one_is() {
        // Loss 2–3 mg/g against 4 mg/g of damage added: the stock grows.
        let growing: Vec<SampleInput> = (0..6)
            .map(|k| sample(k, 40, 2e-3 + 2e-4 * k as f64, Some(4e-3)))
            .collect();
        let b = assess(&growing.iter().collect::<Vec<_>>()).unwrap();
        assert!(!b.balanced, "{b:?}");
        assert!(b.ratio.unwrap() < 0.75, "{b:?}");
        // Scatter about the damage added, both ways: balanced.
        let paid: Vec<SampleInput> = (0..6)
            .map(|k| {
                sample(
                    k,
                    40,
                    4e-3 + if k % 2 == 0 { 1e-3 } else { -1e-3 },
                    Some(4e-3),
                )
            })
            .collect();
        let b = assess(&paid.iter().collect::<Vec<_>>()).unwrap();
        assert!(b.balanced, "{b:?}");
        assert!((b.ratio.unwrap() - 1.0).abs() < 1e-9, "{b:?}");
        assert!(b.describe().contains("lost 4.00"), "{}", b.describe());
    }

    #[test]
    fn a_noisy_loss_short_of_the_floor_is_not_balanced() {
        // 16 samples scattered by ±1.9 mg/g about `loss`, each adding 4.28 mg/g of damage.
        let cell = |loss: f64| -> DamageBalance {
            let samples: Vec<SampleInput> = (0..16)
                .map(|k| {
                    let scatter = if k % 2 == 0 { 1.9e-3 } else { -1.9e-3 };
                    sample(k, 20, loss + scatter, Some(4.28e-3))
                })
                .collect();
            assess(&samples.iter().collect::<Vec<_>>()).unwrap()
        };
        // The 16-per-Dg 45° cell's last window, 3.35 ± 0.49 lost: within the difference
        // test, short of the floor.
        let b = cell(3.35e-3);
        let z = (b.loss_rate - b.damage_rate).abs() / b.difference_sem;
        assert!(z < BALANCE_SIGMAS, "{b:?}");
        assert!((b.ratio.unwrap() - 0.783).abs() < 1e-3, "{b:?}");
        assert!(!b.balanced, "{b:?}");
        // The same scatter about 0.95 of the damage added passes.
        assert!(cell(4.07e-3).balanced);
    }

    #[test]
    fn only_full_recorded_windows_count() {
        let mut s = vec![
            sample(0, 20, 1e-3, Some(1e-3)),
            sample(1, 25, 1e-3, Some(2e-3)),
        ];
        // A sample still short of its window is left out; one is not enough.
        s.push(sample(2, 5, 0.0, Some(0.0)));
        assert_eq!(assess(&s.iter().collect::<Vec<_>>()).unwrap().samples, 2);
        assert!(assess(&s[..1].iter().collect::<Vec<_>>()).is_none());
        // An impact of the window without its damage leaves the balance unknown; one before
        // the window does not.
        s[1].impacts[10].damage_added_kg = None;
        assert!(assess(&s.iter().collect::<Vec<_>>()).is_none());
        s[1].impacts[10].damage_added_kg = Some(0.0);
        s[1].impacts[2].damage_added_kg = None;
        assert!(assess(&s.iter().collect::<Vec<_>>()).is_some());
    }

    #[test]
    fn the_history_follows_each_whole_window_over_the_samples_that_reached_it() {
        // Three samples; the loss steps up from 1 to 4 mg/g at impact 41 against 4 mg/g added.
        let mut s: Vec<SampleInput> = (0..3).map(|k| sample(k, 60, 0.0, Some(4e-3))).collect();
        for (k, x) in s.iter_mut().enumerate() {
            for (i, imp) in x.impacts.iter_mut().enumerate() {
                let base = if i < 40 { 1e-3 } else { 4e-3 };
                imp.mass_loss_kg = (base + 1e-4 * k as f64) * imp.grain_mass_kg;
            }
        }
        // A fourth sample stops at 45: it counts in the first two windows only.
        s.push(sample(3, 45, 1e-3, Some(4e-3)));
        let h = history(&s.iter().collect::<Vec<_>>());
        assert_eq!(h.iter().map(|w| w.end).collect::<Vec<_>>(), [20, 40, 60]);
        assert_eq!(
            h.iter().map(|w| w.balance.samples).collect::<Vec<_>>(),
            [4, 4, 3]
        );
        assert!(
            (h[1].balance.ratio.unwrap() - 1.075 / 4.0).abs() < 1e-9,
            "{h:?}"
        );
        assert!(!h[1].balance.balanced && h[2].balance.balanced, "{h:?}");
        // The last window is the cell's own balance where every sample reached it.
        assert_eq!(
            h[2].balance,
            assess(&s[..3].iter().collect::<Vec<_>>()).unwrap()
        );
        // An impact without damage drops its window only.
        s[0].impacts[5].damage_added_kg = None;
        let h = history(&s.iter().collect::<Vec<_>>());
        assert_eq!(h.iter().map(|w| w.end).collect::<Vec<_>>(), [40, 60]);
    }

    #[test]
    fn the_long_balance_spans_the_last_sixty_impacts_of_the_samples_that_have_them() {
        // The loss is 6 mg/g in impacts 61–80 and 3 before, against 4 added throughout: the
        // last window shows 6, the last 60 (21–80) the mean of 3, 3 and 6.
        let mut s: Vec<SampleInput> = (0..3).map(|k| sample(k, 80, 0.0, Some(4e-3))).collect();
        for (k, x) in s.iter_mut().enumerate() {
            let n = x.impacts.len();
            for (i, imp) in x.impacts.iter_mut().enumerate() {
                let base = if i + BALANCE_POINTS >= n { 6e-3 } else { 3e-3 };
                imp.mass_loss_kg = (base + 1e-4 * k as f64) * imp.grain_mass_kg;
            }
        }
        // A sample short of 60 impacts counts in the last window only.
        s.push(sample(3, 40, 6e-3, Some(4e-3)));
        let all: Vec<&SampleInput> = s.iter().collect();
        let last = assess(&all).unwrap();
        let long = assess_long(&all).unwrap();
        assert_eq!((last.points, last.samples), (BALANCE_POINTS, 4));
        assert_eq!((long.points, long.samples), (LONG_BALANCE_POINTS, 3));
        assert!((long.loss_rate - 4.1e-3).abs() < 1e-12, "{long:?}");
        assert!((last.loss_rate - 6.075e-3).abs() < 1e-12, "{last:?}");
        assert!(assess_long(&all[3..]).is_none());
    }
}
