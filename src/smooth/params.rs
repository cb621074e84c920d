//! Filter choice and parameters, with ALGORITHMS.md's ranges and defaults.

use serde::{Deserialize, Serialize};

/// The smoothing filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Uniform Laplace, `q += lambda L(q)`.
    Laplace,
    /// Taubin lambda/mu low-pass: a lambda step then a mu step per iteration.
    Taubin,
    /// Laplace+HC after Vollmer, Mencl and Mueller 1999.
    Hc,
    /// Windowed sinc (Taubin 1996; VTK's vtkWindowedSincPolyDataFilter).
    Sinc,
}

impl Filter {
    pub const ALL: [Filter; 4] = [Filter::Laplace, Filter::Taubin, Filter::Hc, Filter::Sinc];

    pub fn name(self) -> &'static str {
        match self {
            Filter::Laplace => "laplace",
            Filter::Taubin => "taubin",
            Filter::Hc => "hc",
            Filter::Sinc => "sinc",
        }
    }

    pub fn from_name(name: &str) -> Option<Filter> {
        Filter::ALL.into_iter().find(|f| f.name() == name)
    }
}

impl std::fmt::Display for Filter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A parameter outside its valid range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{name} = {value} is out of range: {valid}")]
pub struct ParamError {
    pub name: &'static str,
    pub value: f64,
    pub valid: &'static str,
}

/// Parameters of every filter; each filter reads the ones it uses.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Params {
    pub filter: Filter,
    pub lambda: f32,
    pub mu: f32,
    pub alpha: f32,
    pub beta: f32,
    pub passband: f32,
    pub iterations: u32,
    /// Displacement bound around the original position (mm); `None` = unbounded.
    pub max_displacement: Option<f32>,
}

impl Params {
    /// ALGORITHMS.md's defaults for `filter` (sinc runs 20 iterations, the others 10).
    pub fn defaults(filter: Filter) -> Self {
        Self {
            filter,
            lambda: 0.5,
            mu: -0.53,
            alpha: 0.1,
            beta: 0.5,
            passband: 0.1,
            iterations: if filter == Filter::Sinc { 20 } else { 10 },
            max_displacement: None,
        }
    }

    /// Refuses out-of-range parameters of the active filter with a message naming the range.
    pub fn validate(&self) -> Result<(), ParamError> {
        fn check(
            name: &'static str,
            value: f64,
            ok: bool,
            valid: &'static str,
        ) -> Result<(), ParamError> {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(ParamError { name, value, valid })
            }
        }
        // Through the shortest decimal form, so a message says "-0.3", not "-0.30000001192".
        let wide = |v: f32| v.to_string().parse::<f64>().unwrap_or(v as f64);
        let (l, m, a, b, p) = (
            wide(self.lambda),
            wide(self.mu),
            wide(self.alpha),
            wide(self.beta),
            wide(self.passband),
        );
        let it = self.iterations as f64;
        match self.filter {
            Filter::Laplace => {
                check("lambda", l, (0.0..=1.0).contains(&l), "[0, 1]")?;
                check("iterations", it, self.iterations <= 50, "[0, 50]")?;
            }
            Filter::Taubin => {
                check("lambda", l, l > 0.0 && l <= 1.0, "(0, 1]")?;
                check("mu", m, (-1.0..0.0).contains(&m), "[-1, 0)")?;
                check("mu", m, m < -l, "mu < -lambda")?;
                check("iterations", it, self.iterations <= 50, "[0, 50]")?;
            }
            Filter::Hc => {
                check("alpha", a, (0.0..=1.0).contains(&a), "[0, 1]")?;
                check("beta", b, (0.0..=1.0).contains(&b), "[0, 1]")?;
                check("iterations", it, self.iterations <= 50, "[0, 50]")?;
            }
            Filter::Sinc => {
                check("passband", p, p > 0.0 && p < 2.0, "(0, 2)")?;
                check(
                    "iterations",
                    it,
                    (1..=100).contains(&self.iterations),
                    "[1, 100]",
                )?;
            }
        }
        if let Some(d) = self.max_displacement {
            check("max_displacement", wide(d), d >= 0.0, "a distance >= 0 mm")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        for f in Filter::ALL {
            Params::defaults(f).validate().unwrap();
            assert_eq!(Filter::from_name(f.name()), Some(f));
        }
    }

    #[test]
    fn out_of_range_is_refused_with_the_range() {
        let mut p = Params::defaults(Filter::Taubin);
        p.mu = -0.4;
        let e = p.validate().unwrap_err();
        assert_eq!(e.name, "mu");
        assert!(e.to_string().contains("mu < -lambda"));
        let mut p = Params::defaults(Filter::Sinc);
        p.iterations = 0;
        assert!(p.validate().unwrap_err().to_string().contains("[1, 100]"));
        let mut p = Params::defaults(Filter::Laplace);
        p.lambda = f32::NAN;
        assert!(p.validate().is_err());
    }
}
