//! Filter parameters from the command line: ALGORITHMS.md's defaults, overridden by flags,
//! refused with the valid range when out of it.

use crate::smooth::{Filter, Params};
use clap::Args;

#[derive(Args, Clone, Debug, Default)]
pub(super) struct FilterArgs {
    /// laplace | taubin | hc | sinc
    #[arg(long, default_value = "hc")]
    pub filter: String,
    /// Iterations (laplace/taubin/hc [0,50], default 10; sinc [1,100], default 20).
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Laplace and Taubin step factor.
    #[arg(long)]
    pub lambda: Option<f32>,
    /// Taubin's second (negative) step factor, mu < -lambda.
    #[arg(long, allow_hyphen_values = true)]
    pub mu: Option<f32>,
    /// HC: pull towards the original positions [0,1].
    #[arg(long)]
    pub alpha: Option<f32>,
    /// HC: pull towards the previous positions [0,1].
    #[arg(long)]
    pub beta: Option<f32>,
    /// Windowed sinc pass band (0,2).
    #[arg(long)]
    pub passband: Option<f32>,
    /// Bound on each vertex's displacement from its original position (mesh units, mm).
    #[arg(long = "max-displacement")]
    pub max_displacement: Option<f32>,
}

pub(super) fn filter(name: &str) -> Result<Filter, String> {
    Filter::from_name(name)
        .ok_or_else(|| format!("unknown filter '{name}': use laplace, taubin, hc or sinc"))
}

impl FilterArgs {
    /// The parameters these flags describe, validated.
    pub fn params(&self) -> Result<Params, String> {
        let mut p = Params::defaults(filter(&self.filter)?);
        if let Some(v) = self.iterations {
            p.iterations = v;
        }
        if let Some(v) = self.lambda {
            p.lambda = v;
        }
        if let Some(v) = self.mu {
            p.mu = v;
        }
        if let Some(v) = self.alpha {
            p.alpha = v;
        }
        if let Some(v) = self.beta {
            p.beta = v;
        }
        if let Some(v) = self.passband {
            p.passband = v;
        }
        p.max_displacement = self.max_displacement;
        p.validate().map_err(|e| e.to_string())?;
        Ok(p)
    }
}
