//! [`CommonOptions`]: the options both back ends read with one meaning — termination,
//! the bounds of the gradient-based scaling, output — embedded in
//! [`IpmOptions`](crate::IpmOptions) and [`SqpOptions`](crate::SqpOptions).
//!
//! The embedding is flat for every way users set options: in Rust through `Deref`
//! (`opts.tol = 1e-10` on an `IpmOptions`), in text through `#[serde(flatten)]`
//! (`"tol": 1e-10` in JSON, `tol=1e-10` with
//! [`NamedOptions::set_by_name`](crate::NamedOptions::set_by_name) and the CLI's
//! `--opt`). Unknown keys stay errors: serde's `deny_unknown_fields` does not work with
//! `flatten`, so `strict_options_serde!` checks the keys itself.

use serde::{Deserialize, Serialize};

use crate::error::SolveError;

/// Options with the same name, meaning and default in both back ends (IPOPT's names).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CommonOptions {
    // ---------- termination ----------
    /// Desired relative (scaled) convergence tolerance on the KKT error. Default 1e-8.
    pub tol: f64,
    /// Scaling threshold s_max for the NLP error. Default 100.
    pub s_max: f64,
    /// Maximum number of iterations (the IPM's restoration iterations included).
    /// Default 3000.
    pub max_iter: usize,
    /// Maximum wall-clock time in seconds. Default 1e20.
    pub max_wall_time: f64,
    /// Absolute tolerance on (unscaled) dual infeasibility. Default 1.
    pub dual_inf_tol: f64,
    /// Absolute tolerance on (unscaled) constraint violation. Default 1e-4.
    pub constr_viol_tol: f64,
    /// Absolute tolerance on (unscaled) complementarity. Default 1e-4.
    pub compl_inf_tol: f64,
    /// "Acceptable" relative convergence tolerance. Default 1e-6.
    pub acceptable_tol: f64,
    /// Number of consecutive acceptable iterates before stopping. Default 15 (0 disables).
    pub acceptable_iter: usize,
    /// Acceptable dual infeasibility. Default 1e10.
    pub acceptable_dual_inf_tol: f64,
    /// Acceptable constraint violation. Default 1e-2.
    pub acceptable_constr_viol_tol: f64,
    /// Acceptable complementarity. Default 1e-2.
    pub acceptable_compl_inf_tol: f64,
    /// Acceptable relative objective change between iterations. Default 1e20.
    pub acceptable_obj_change_tol: f64,
    /// Iterates with a component larger than this in magnitude are diverging. Default 1e20.
    pub diverging_iterates_tol: f64,
    // ---------- scaling ----------
    /// Maximum gradient after the gradient-based scaling. Default 100.
    pub nlp_scaling_max_gradient: f64,
    /// Minimum scaling factor. Default 1e-8.
    pub nlp_scaling_min_value: f64,
    // ---------- output ----------
    /// 0: silent; ≥ 3: summary; ≥ 5: iteration table. Default 0.
    pub print_level: u8,
}

impl Default for CommonOptions {
    fn default() -> Self {
        Self::DEFAULTS
    }
}

impl CommonOptions {
    /// IPOPT's defaults, as a constant (the back ends' option defaults start from it).
    pub(crate) const DEFAULTS: CommonOptions = CommonOptions {
        tol: 1e-8,
        s_max: 100.0,
        max_iter: 3000,
        max_wall_time: 1e20,
        dual_inf_tol: 1.0,
        constr_viol_tol: 1e-4,
        compl_inf_tol: 1e-4,
        acceptable_tol: 1e-6,
        acceptable_iter: 15,
        acceptable_dual_inf_tol: 1e10,
        acceptable_constr_viol_tol: 1e-2,
        acceptable_compl_inf_tol: 1e-2,
        acceptable_obj_change_tol: 1e20,
        diverging_iterates_tol: 1e20,
        nlp_scaling_max_gradient: 100.0,
        nlp_scaling_min_value: 1e-8,
        print_level: 0,
    };
}

impl CommonOptions {
    /// Checks every option; the error names the first bad field.
    pub fn validate(&self) -> Result<(), SolveError> {
        macro_rules! positive {
            ($($f:ident),*) => {$(
                if self.$f.is_nan() || self.$f <= 0.0 || !self.$f.is_finite() {
                    return Err(SolveError::InvalidOption {
                        field: stringify!($f),
                        reason: format!("must be finite and > 0, got {}", self.$f),
                    });
                }
            )*};
        }
        positive!(
            tol,
            s_max,
            max_wall_time,
            dual_inf_tol,
            constr_viol_tol,
            compl_inf_tol,
            acceptable_tol,
            acceptable_dual_inf_tol,
            acceptable_constr_viol_tol,
            acceptable_compl_inf_tol,
            acceptable_obj_change_tol,
            diverging_iterates_tol,
            nlp_scaling_max_gradient,
            nlp_scaling_min_value
        );
        if self.max_iter == 0 {
            return Err(SolveError::InvalidOption {
                field: "max_iter",
                reason: "must be at least 1".into(),
            });
        }
        if self.acceptable_tol < self.tol {
            return Err(SolveError::InvalidOption {
                field: "acceptable_tol",
                reason: "must be >= tol".into(),
            });
        }
        Ok(())
    }
}

/// Implements, for an options struct with a `common: CommonOptions` field:
/// `Deref`/`DerefMut` to [`CommonOptions`] (so `opts.tol` reads and writes), and
/// `Serialize`/`Deserialize` through the struct's derived (`remote = "Self"`) code with
/// unknown keys rejected (the flattened form cannot use `deny_unknown_fields`).
macro_rules! strict_options_serde {
    ($t:ty) => {
        impl std::ops::Deref for $t {
            type Target = $crate::frontend::CommonOptions;
            fn deref(&self) -> &Self::Target {
                &self.common
            }
        }

        impl std::ops::DerefMut for $t {
            fn deref_mut(&mut self) -> &mut Self::Target {
                &mut self.common
            }
        }

        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                <$t>::serialize(self, s)
            }
        }

        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                use serde::de::Error;
                let map = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
                let known = match <$t>::serialize(&<$t>::default(), serde_json::value::Serializer) {
                    Ok(serde_json::Value::Object(k)) => k,
                    _ => return Err(D::Error::custom("options do not serialise to a map")),
                };
                if let Some(key) = map.keys().find(|k| !known.contains_key(*k)) {
                    let mut valid: Vec<&str> = known.keys().map(String::as_str).collect();
                    valid.sort_unstable();
                    return Err(D::Error::custom(format!(
                        "unknown option '{key}'; valid options: {}",
                        valid.join(", ")
                    )));
                }
                <$t>::deserialize(serde_json::Value::Object(map)).map_err(D::Error::custom)
            }
        }
    };
}
pub(crate) use strict_options_serde;
