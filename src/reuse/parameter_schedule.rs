//! Schedules of a parameter over the steps of a run (SAP-Net's temperature τ).

use serde::{Deserialize, Serialize};

/// A value that moves from `from` at step 0 to `to` at step `steps`, then stays at `to`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Schedule {
    /// `from + (to − from)·t/steps`.
    Linear { from: f64, to: f64, steps: u64 },
    /// `from·(to/from)^(t/steps)`: equal ratios in equal times.
    Exponential { from: f64, to: f64, steps: u64 },
}

impl Schedule {
    /// The value at step `t`; exactly `from` at 0 and exactly `to` from `steps` on.
    pub fn at(&self, t: u64) -> f64 {
        let (Self::Linear { from, to, steps } | Self::Exponential { from, to, steps }) = *self;
        if t >= steps {
            return to;
        }
        let progress = t as f64 / steps as f64;
        match self {
            Self::Linear { .. } => from + (to - from) * progress,
            Self::Exponential { .. } => from * (to / from).powf(progress),
        }
    }

    /// Both ends finite and > 0 (a temperature), and a length of at least one step;
    /// `field` names the schedule in the message.
    pub fn validate_positive(&self, field: &str) -> Result<(), String> {
        let (Self::Linear { from, to, steps } | Self::Exponential { from, to, steps }) = *self;
        for (name, value) in [("from", from), ("to", to)] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(format!(
                    "field `{field}.{name}`: expected a finite number > 0, got {value:?}"
                ));
            }
        }
        if !(1..=crate::limits::MAX_STEPS).contains(&steps) {
            return Err(format!(
                "field `{field}.steps`: expected 1 to {}, got {steps}",
                crate::limits::MAX_STEPS
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_hit_their_endpoints() {
        let linear = Schedule::Linear {
            from: 4.0,
            to: 0.1,
            steps: 1000,
        };
        let exponential = Schedule::Exponential {
            from: 4.0,
            to: 0.1,
            steps: 1000,
        };
        for s in [linear, exponential] {
            assert_eq!(s.at(0), 4.0);
            assert_eq!(s.at(1000), 0.1);
            assert_eq!(s.at(5000), 0.1);
        }
        // Half-way: the mean of the ends, and their geometric mean (√0.4).
        assert!((linear.at(500) - 2.05).abs() < 1e-12);
        assert!((exponential.at(500) - 0.4f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn a_temperature_schedule_must_stay_positive() {
        let s = Schedule::Linear {
            from: 1.0,
            to: 0.0,
            steps: 10,
        };
        let err = s
            .validate_positive("protocol.methods[1].temperature")
            .unwrap_err();
        assert_eq!(
            err,
            "field `protocol.methods[1].temperature.to`: expected a finite number > 0, got 0.0"
        );
        let s = Schedule::Exponential {
            from: 1.0,
            to: 2.0,
            steps: 0,
        };
        assert!(s.validate_positive("t").unwrap_err().contains("`t.steps`"));
    }
}
