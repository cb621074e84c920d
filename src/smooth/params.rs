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
    /// How many of the iteration counts `at` (ascending) leave the mesh as it is: the zeros, or
    /// every count when no iteration moves a vertex (uniform Laplace with lambda 0), so a caller
    /// can answer them without smoothing.
    pub fn unchanged_counts(&self, at: &[u32]) -> usize {
        if self.filter == Filter::Laplace && self.lambda == 0.0 {
            return at.len();
        }
        at.iter().take_while(|&&k| k == 0).count()
    }

    /// ALGORITHMS.md's defaults for `filter` (sinc runs 20 iterations, the others 10).
    pub const fn defaults(filter: Filter) -> Self {
        Self {
            filter,
            lambda: 0.5,
            mu: -0.53,
            alpha: 0.1,
            beta: 0.5,
            passband: 0.1,
            iterations: if matches!(filter, Filter::Sinc) {
                20
            } else {
                10
            },
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
        let wide = shortest;
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

impl Params {
    /// The parameters this filter reads as `name value` pairs, e.g. `lambda 0.5, iterations 10`
    /// (an unset displacement bound left out).
    pub fn describe(&self) -> String {
        match self.to_json() {
            serde_json::Value::Object(m) => m
                .into_iter()
                .filter(|(_, v)| !v.is_null())
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", "),
            _ => String::new(),
        }
    }

    /// The parameters this filter reads, as JSON (the others are left out so a report is not
    /// misread): the `params` object of the CLI's reports and of the embedding API.
    pub fn to_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        let mut put = |k: &str, v: f32| {
            m.insert(k.to_string(), serde_json::json!(shortest(v)));
        };
        match self.filter {
            Filter::Laplace => put("lambda", self.lambda),
            Filter::Taubin => {
                put("lambda", self.lambda);
                put("mu", self.mu);
            }
            Filter::Hc => {
                put("alpha", self.alpha);
                put("beta", self.beta);
            }
            Filter::Sinc => put("passband", self.passband),
        }
        m.insert("iterations".into(), serde_json::json!(self.iterations));
        m.insert(
            "max_displacement".into(),
            serde_json::json!(self.max_displacement.map(shortest)),
        );
        serde_json::Value::Object(m)
    }

    /// These parameters with the values of a JSON object applied: any of the keys
    /// `lambda mu alpha beta passband iterations max_displacement` (`max_displacement: null`
    /// removes the bound). All or nothing: an unknown key, a value of the wrong type or a
    /// result out of range is refused with a message naming it, and `self` is left as it was.
    pub fn with_json(&self, values: &serde_json::Value) -> Result<Params, String> {
        let object = values
            .as_object()
            .ok_or_else(|| format!("parameters must be an object, not {values}"))?;
        let mut p = *self;
        for (key, value) in object {
            let number = || {
                value
                    .as_f64()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("{key} must be a finite number, not {value}"))
            };
            match key.as_str() {
                "lambda" => p.lambda = number()? as f32,
                "mu" => p.mu = number()? as f32,
                "alpha" => p.alpha = number()? as f32,
                "beta" => p.beta = number()? as f32,
                "passband" => p.passband = number()? as f32,
                "iterations" => {
                    p.iterations = value
                        .as_u64()
                        .and_then(|v| u32::try_from(v).ok())
                        .ok_or_else(|| {
                            format!("iterations must be a whole number >= 0, not {value}")
                        })?
                }
                "max_displacement" => {
                    p.max_displacement = match value {
                        serde_json::Value::Null => None,
                        _ => Some(number()? as f32),
                    }
                }
                other => {
                    return Err(format!(
                        "unknown parameter '{other}': use lambda, mu, alpha, beta, passband, \
                         iterations or max_displacement"
                    ))
                }
            }
        }
        p.validate().map_err(|e| e.to_string())?;
        Ok(p)
    }
}

/// An f32 as the f64 with the same shortest decimal form (0.1f32 prints as 0.1, not
/// 0.10000000149).
pub fn shortest(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(v as f64)
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

    #[test]
    fn json_values_apply_all_or_nothing() {
        let hc = Params::defaults(Filter::Hc);
        let p = hc
            .with_json(
                &serde_json::json!({"alpha": 0.2, "iterations": 30, "max_displacement": 0.5}),
            )
            .unwrap();
        assert_eq!(
            (p.alpha, p.iterations, p.max_displacement),
            (0.2, 30, Some(0.5))
        );
        assert_eq!(
            p.to_json(),
            serde_json::json!({"alpha": 0.2, "beta": 0.5, "iterations": 30, "max_displacement": 0.5})
        );
        let cleared = p
            .with_json(&serde_json::json!({"max_displacement": null}))
            .unwrap();
        assert_eq!(cleared.max_displacement, None);

        let refused = |v: serde_json::Value, needle: &str| {
            let e = hc.with_json(&v).unwrap_err();
            assert!(e.contains(needle), "{v}: {e}");
        };
        refused(serde_json::json!({"iterations": 1000}), "[0, 50]");
        refused(serde_json::json!({"iterations": 2.5}), "whole number");
        refused(serde_json::json!({"alpha": "x"}), "finite number");
        refused(serde_json::json!({"gamma": 1}), "unknown parameter 'gamma'");
        refused(serde_json::json!([1]), "must be an object");
        // A valid key beside a refused one changes nothing.
        assert!(hc
            .with_json(&serde_json::json!({"beta": 0.1, "alpha": 7}))
            .is_err());
        assert_eq!(hc, Params::defaults(Filter::Hc));
    }
}
