//! JSON parsing that rejects duplicate keys.
//!
//! `serde_json` keeps the last of two equal keys in an object without a word, so a
//! scenario with `"n_step": 30` written twice would silently take the second value;
//! TOML rejects such a file. [`parse`] reads JSON into a [`serde_json::Value`] as
//! `serde_json::from_str` does, but fails on a key repeated within one object, naming
//! its dotted path (`gap.min`; array elements as `[i]`).
use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::fmt;

/// Parses JSON text, rejecting a key that appears twice in the same object.
pub fn parse(text: &str) -> Result<Value, serde_json::Error> {
    let mut d = serde_json::Deserializer::from_str(text);
    let v = Strict {
        path: String::new(),
    }
    .deserialize(&mut d)?;
    d.end()?;
    Ok(v)
}

/// A value at a dotted path (the path names a duplicate in the error).
struct Strict {
    path: String,
}

impl Strict {
    fn child(&self, key: &str) -> Strict {
        Strict {
            path: if self.path.is_empty() {
                key.to_string()
            } else {
                format!("{}.{key}", self.path)
            },
        }
    }
}

impl<'de> DeserializeSeed<'de> for Strict {
    type Value = Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Strict {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = m.next_key::<String>()? {
            let child = self.child(&key);
            if out.contains_key(&key) {
                return Err(de::Error::custom(format!("duplicate key `{}`", child.path)));
            }
            let v = m.next_value_seed(child)?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut s: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(v) = s.next_element_seed(Strict {
            path: format!("{}[{}]", self.path, out.len()),
        })? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E: de::Error>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_values_as_serde_json_without_duplicates() {
        let text = r#"{"a": 1, "b": [1.5, -2, "x", null, true, {"c": {}}], "d": {"e": 1e300}}"#;
        let ours = parse(text).unwrap();
        let theirs: Value = serde_json::from_str(text).unwrap();
        assert_eq!(ours, theirs);
    }

    #[test]
    fn duplicates_are_named_by_path() {
        let e = parse(r#"{"n_step": 30, "n_step": 40}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("duplicate key `n_step`"), "{e}");
        let e = parse(r#"{"gap": {"min": 1, "max": 2, "min": 3}}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("duplicate key `gap.min`"), "{e}");
        let e = parse(r#"{"a": [{"k": 1}, {"k": 1, "k": 2}]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("duplicate key `a[1].k`"), "{e}");
        // The same key in different objects is fine; trailing text is not.
        assert!(parse(r#"{"a": {"k": 1}, "b": {"k": 1}}"#).is_ok());
        assert!(parse(r#"{"a": 1} x"#).is_err());
    }
}
