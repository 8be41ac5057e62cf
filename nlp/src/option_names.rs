//! Setting solver options by name from text, as IPOPT's options file and
//! `SetStringValue`/`SetNumericValue` do: `"tol=1e-10"`, `"mu_strategy=adaptive"`.
//!
//! Names and types are those of the options struct's fields (its serde form), so every
//! option of [`IpmOptions`] and [`SqpOptions`] can be set this way with no list to keep
//! in sync. A value is read as the field's type — a number, `true`/`false`, or the
//! kebab-case name of an enum value — and the result is validated as a whole.
//!
//! ```
//! use nlp::{IpmOptions, NamedOptions};
//! let mut o = IpmOptions::default();
//! o.set_by_name(&["tol=1e-10", "max_iter=500", "mu_strategy=adaptive"]).unwrap();
//! assert_eq!((o.tol, o.max_iter), (1e-10, 500));
//! let err = o.set_by_name(&["toll=1"]).unwrap_err();
//! assert!(err.to_string().starts_with("unknown option 'toll' (did you mean 'tol'?)"));
//! ```
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::{Map, Number, Value};

use crate::error::SolveError;
use crate::options::IpmOptions;
use crate::sqp::SqpOptions;

/// Why an option assignment was refused; each names the option.
#[derive(Debug, thiserror::Error)]
pub enum OptionError {
    /// Not of the form `KEY=VALUE`.
    #[error("'{0}': expected KEY=VALUE")]
    Syntax(String),
    /// No option of that name; the message first names the valid options nearest to it
    /// (edit distance), if any is close.
    #[error("unknown option '{key}'{}; valid options: {valid}", near_names(.key, .valid))]
    Unknown {
        /// The name given.
        key: String,
        /// Every option name, sorted, comma-separated.
        valid: String,
    },
    /// The value cannot be read as the option's type.
    #[error("option '{key}': bad value '{value}': {reason}")]
    BadValue {
        /// Option name.
        key: String,
        /// The value given.
        value: String,
        /// Why, e.g. "expected a number (default 1e-8)".
        reason: String,
    },
    /// The value has the right type but is out of range ([`NamedOptions::check`]).
    #[error(transparent)]
    Invalid(#[from] SolveError),
}

/// " (did you mean 'a' or 'b'?)" for the names in the comma-separated `valid` within
/// Damerau–Levenshtein distance max(1, len/3) of `key` (nearest first, at most 3), or "".
fn near_names(key: &str, valid: &str) -> String {
    let limit = (key.chars().count() / 3).max(1);
    let mut near: Vec<(usize, &str)> = valid
        .split(", ")
        .map(|v| (strsim::damerau_levenshtein(key, v), v))
        .filter(|&(d, _)| d <= limit)
        .collect();
    near.sort();
    near.truncate(3);
    match near.as_slice() {
        [] => String::new(),
        [only] => format!(" (did you mean '{}'?)", only.1),
        [first @ .., last] => {
            let first: Vec<String> = first.iter().map(|(_, v)| format!("'{v}'")).collect();
            format!(" (did you mean {} or '{}'?)", first.join(", "), last.1)
        }
    }
}

/// Options that can be set by name from text.
pub trait NamedOptions: Serialize + DeserializeOwned {
    /// Checks every option; the error names the first bad one.
    fn check(&self) -> Result<(), SolveError>;

    /// Applies `KEY=VALUE` assignments in order; on any error `self` is left unchanged.
    fn set_by_name<S: AsRef<str>>(&mut self, assignments: &[S]) -> Result<(), OptionError> {
        let mut fields = match serde_json::to_value(&*self) {
            Ok(Value::Object(map)) => map,
            _ => unreachable!("options structs serialise to a map"),
        };
        for a in assignments {
            let a = a.as_ref();
            let (key, value) = a
                .split_once('=')
                .ok_or_else(|| OptionError::Syntax(a.to_string()))?;
            let (key, value) = (key.trim(), value.trim());
            let new = parse_value(&fields, key, value)?;
            // Deserialise with this one change, so that a value of the right JSON type
            // but not the field's (1.5 for an integer, 300 for a u8, an unknown enum
            // name) is reported against its own key.
            let mut trial = fields.clone();
            trial.insert(key.to_string(), new);
            if let Err(e) = serde_json::from_value::<Self>(Value::Object(trial.clone())) {
                return Err(OptionError::BadValue {
                    key: key.to_string(),
                    value: value.to_string(),
                    reason: e.to_string(),
                });
            }
            fields = trial;
        }
        let new: Self = serde_json::from_value(Value::Object(fields))
            .expect("every field was deserialised above");
        new.check()?;
        *self = new;
        Ok(())
    }
}

/// The JSON value of `value` for the field `key`, typed like the field's current value.
fn parse_value(fields: &Map<String, Value>, key: &str, value: &str) -> Result<Value, OptionError> {
    let old = fields.get(key).ok_or_else(|| {
        let mut keys: Vec<&str> = fields.keys().map(String::as_str).collect();
        keys.sort_unstable();
        OptionError::Unknown {
            key: key.to_string(),
            valid: keys.join(", "),
        }
    })?;
    let parsed = match old {
        Value::Bool(_) => match value {
            "true" | "yes" => Some(Value::Bool(true)),
            "false" | "no" => Some(Value::Bool(false)),
            _ => None,
        },
        Value::Number(_) => {
            if let Ok(u) = value.parse::<u64>() {
                Some(Value::from(u))
            } else if let Ok(i) = value.parse::<i64>() {
                Some(Value::from(i))
            } else {
                value
                    .parse::<f64>()
                    .ok()
                    .and_then(Number::from_f64)
                    .map(Value::Number)
            }
        }
        Value::String(_) => Some(Value::String(value.to_string())),
        // An optional switch (default None), set with IPOPT's words too.
        Value::Null if matches!(value, "yes" | "no") => Some(Value::Bool(value == "yes")),
        // An optional number, or an optional enum by its kebab-case name.
        Value::Null => serde_json::from_str(value)
            .ok()
            .or_else(|| Some(Value::String(value.to_string()))),
        _ => serde_json::from_str(value).ok(),
    };
    parsed.ok_or_else(|| OptionError::BadValue {
        key: key.to_string(),
        value: value.to_string(),
        reason: match old {
            Value::Bool(_) => format!("expected true or false (default {old})"),
            Value::Number(_) => format!("expected a number (default {old})"),
            _ => format!("expected a value like the default {old}"),
        },
    })
}

impl NamedOptions for IpmOptions {
    fn check(&self) -> Result<(), SolveError> {
        self.validate()
    }
}

impl NamedOptions for SqpOptions {
    fn check(&self) -> Result<(), SolveError> {
        self.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::near_names;

    #[test]
    fn near_names_are_close_and_nearest_first() {
        let valid = "acceptable_tol, max_iter, max_wall_time, mu_init, tol";
        assert_eq!(near_names("toll", valid), " (did you mean 'tol'?)");
        assert_eq!(near_names("max_itr", valid), " (did you mean 'max_iter'?)");
        assert_eq!(near_names("mu_inti", valid), " (did you mean 'mu_init'?)");
        assert_eq!(near_names("zzz", valid), "");
        let valid = "bound_frac, bound_push, slack_bound_frac";
        assert_eq!(
            near_names("bound_fracc", valid),
            " (did you mean 'bound_frac'?)"
        );
        assert_eq!(
            near_names("bound_pash", valid),
            " (did you mean 'bound_push'?)"
        );
        let valid = "tol, tal, til";
        assert_eq!(
            near_names("tul", valid),
            " (did you mean 'tal', 'til' or 'tol'?)"
        );
    }
}
