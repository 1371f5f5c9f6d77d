//! Errors: bad input names its field and rule; a failed simulation names step, particle and quantity.

use thiserror::Error;

/// A rejected input: `field` is the dotted path of the offending value, `rule` what it broke.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{field}: {rule}")]
pub struct InputError {
    /// Dotted path of the field, e.g. `material.poisson_ratio`.
    pub field: String,
    /// The rule that the value broke.
    pub rule: String,
}

impl InputError {
    /// Builds an error for `field` breaking `rule`.
    pub fn new(field: impl Into<String>, rule: impl Into<String>) -> Self {
        InputError {
            field: field.into(),
            rule: rule.into(),
        }
    }

    /// A number as an error message quotes it: plain between 1e-3 and 1e6, in exponent form
    /// outside, so a typo of 1e308 does not print three hundred digits.
    pub fn shown(v: f64) -> String {
        if v == 0.0 || !v.is_finite() || (1e-3..1e6).contains(&v.abs()) {
            format!("{v}")
        } else {
            format!("{v:e}")
        }
    }

    /// Checks an upper bound: `v` at most `max` `unit`, `why` saying where the bound comes from.
    pub fn require_at_most(
        field: impl Into<String>,
        v: f64,
        max: f64,
        unit: &str,
        why: &str,
    ) -> Result<(), InputError> {
        if v <= max {
            return Ok(());
        }
        Err(InputError::new(
            field,
            format!(
                "must be at most {max} {unit} ({why}), got {}",
                InputError::shown(v)
            ),
        ))
    }

    /// Checks the rule most physical inputs share: a finite number > 0 (errors name the field and
    /// the rule: docs/design.md#rules-the-engine-keeps).
    pub fn require_positive(field: impl Into<String>, v: f64) -> Result<(), InputError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(InputError::new(
                field,
                format!("must be a finite number > 0, got {}", InputError::shown(v)),
            ))
        }
    }
}

/// A simulation that went unstable (it never fails silently: docs/design.md#rules-the-engine-keeps).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("simulation failed at step {step} (t = {time_s:.6e} s): {what}")]
pub struct SimError {
    /// Step number at which the check fired.
    pub step: u64,
    /// Simulated time at that step (s).
    pub time_s: f64,
    /// What went wrong, naming the particle or body and the quantity.
    pub what: String,
}
