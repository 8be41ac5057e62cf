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
//! assert!(err.to_string().contains("unknown option 'toll'"));
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
    /// No option of that name.
    #[error("unknown option '{key}'; valid options: {valid}")]
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
