//! Reading a scenario: files (TOML or JSON), partial values merged into the defaults with
//! unknown fields and wrong types named by their dotted path, `--set` overrides, and the
//! files a scenario refers to (a height map's CSV).

use super::{read_height_csv, Scenario, ScenarioError, TerrainSpec};
use serde_json::Value;
use std::path::Path;

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "nothing (null)",
        Value::Bool(_) => "a boolean",
        Value::Number(n) if n.is_u64() => "a non-negative integer",
        Value::Number(_) => "a number",
        Value::String(_) => "text",
        Value::Array(_) => "an array",
        Value::Object(_) => "a table",
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The `motion` limits are serialised only when set: before merging into them, the
/// unset ones are added as nulls (so that `--set motion.KEY=…` and a file's `[motion]`
/// table find them).
fn add_unset_limits(b: &mut serde_json::Map<String, Value>) {
    let all = super::MotionLimits {
        body_height_min: Some(0.0),
        body_height_max: Some(0.0),
        com_travel_max: Some(0.0),
    };
    let Ok(Value::Object(names)) = serde_json::to_value(all) else {
        return;
    };
    let table = b
        .entry("motion")
        .or_insert_with(|| Value::Object(Default::default()));
    if let Value::Object(t) = table {
        for name in names.keys() {
            t.entry(name.clone()).or_insert(Value::Null);
        }
    }
}

/// Deep-merges `patch` into `base` (the serialised defaults). Keys absent from `base` are
/// unknown fields; a value of another kind than the default's is a type error. Both are
/// reported with the dotted path, which serde's own errors do not give.
fn merge(base: &mut Value, patch: Value, path: &str) -> Result<(), ScenarioError> {
    match (base, patch) {
        (Value::Object(b), Value::Object(p)) => {
            for (key, pv) in p {
                let here = join(path, &key);
                if here == "motion" {
                    add_unset_limits(b);
                }
                match b.get_mut(&key) {
                    Some(bv) if here == "terrain" => merge_terrain(bv, pv)?,
                    Some(bv) => merge(bv, pv, &here)?,
                    None => {
                        return Err(ScenarioError::UnknownField {
                            field: here,
                            known: b.keys().cloned().collect::<Vec<_>>().join(", "),
                        })
                    }
                }
            }
            Ok(())
        }
        (Value::Array(b), Value::Array(p)) => {
            if b.len() != p.len() {
                return Err(ScenarioError::WrongType {
                    field: path.to_string(),
                    expected: format!("an array of {} numbers", b.len()),
                    found: format!("an array of {}", p.len()),
                });
            }
            for (i, (bv, pv)) in b.iter_mut().zip(p).enumerate() {
                merge(bv, pv, &format!("{path}[{i}]"))?;
            }
            Ok(())
        }
        (b @ Value::Number(_), Value::Number(p)) => {
            if b.is_u64() && !p.is_u64() {
                return Err(ScenarioError::WrongType {
                    field: path.to_string(),
                    expected: "a non-negative integer".into(),
                    found: p.to_string(),
                });
            }
            *b = Value::Number(p);
            Ok(())
        }
        // An optional value not set yet (the `motion` limits).
        (b @ Value::Null, p @ Value::Number(_)) => {
            *b = p;
            Ok(())
        }
        (b @ Value::String(_), p @ Value::String(_)) => {
            *b = p;
            Ok(())
        }
        (b, p) => Err(ScenarioError::WrongType {
            field: path.to_string(),
            expected: kind(b).to_string(),
            found: match &p {
                Value::Object(_) | Value::Array(_) => kind(&p).to_string(),
                _ => format!("{} ({p})", kind(&p)),
            },
        }),
    }
}

/// Merges a `terrain` table: a different `kind` replaces the table (its fields are the
/// new kind's, checked by serde); the same kind (or none given) overrides field by field.
fn merge_terrain(base: &mut Value, patch: Value) -> Result<(), ScenarioError> {
    let Value::Object(p) = patch else {
        return Err(ScenarioError::WrongType {
            field: "terrain".into(),
            expected: "a table with a `kind`".into(),
            found: kind(&patch).into(),
        });
    };
    let same_kind = p.get("kind").is_none_or(|k| base.get("kind") == Some(k));
    match base {
        Value::Object(b) if same_kind => {
            // A new CSV file: its heights are read again.
            if p.contains_key("file") && !p.contains_key("heights") {
                b.remove("heights");
            }
            for (k, v) in p {
                b.insert(k, v);
            }
        }
        _ => *base = Value::Object(p),
    }
    Ok(())
}

/// Other names a scenario may give a value, as the specification's table and the
/// source's equations spell them (`gap_min`, `F_thr`, `w_CoM`, `m1`, ...), with the
/// dotted path of the value they name. Scenarios written by other implementations of
/// the specification use them; they are read as the canonical key (and written back
/// under it).
pub const ALIASES: [(&str, &str); 24] = [
    ("gap_min", "gap.min"),
    ("gap_max", "gap.max"),
    ("depth", "gap.depth"),
    ("D", "gap.depth"),
    ("steepness", "gap.steepness"),
    ("k", "gap.steepness"),
    ("margin", "gap.margin"),
    ("safety_margin", "gap.margin"),
    ("gap.D", "gap.depth"),
    ("gap.k", "gap.steepness"),
    ("gap.safety_margin", "gap.margin"),
    ("mu", "friction.mu"),
    ("f_thr", "friction.f_thr"),
    ("F_thr", "friction.f_thr"),
    ("friction.F_thr", "friction.f_thr"),
    ("w_com", "weights.com"),
    ("w_CoM", "weights.com"),
    ("w_f", "weights.force"),
    ("w_F", "weights.force"),
    ("weights.w_CoM", "weights.com"),
    ("weights.w_F", "weights.force"),
    ("m1", "masses.B"),
    ("m2", "masses.F"),
    ("nstep", "n_step"),
];

/// Moves every aliased key of `v` ([`ALIASES`]) to its canonical place; a value given
/// under two names is an error naming both.
fn canonical_keys(mut v: Value) -> Result<Value, ScenarioError> {
    for (alias, canonical) in ALIASES {
        let (parent, key) = match alias.split_once('.') {
            Some((p, k)) => (Some(p), k),
            None => (None, alias),
        };
        let table = match parent {
            Some(p) => v.get_mut(p).and_then(Value::as_object_mut),
            None => v.as_object_mut(),
        };
        let Some(value) = table.and_then(|t| t.remove(key)) else {
            continue;
        };
        let (cp, ck) = canonical.split_once('.').unwrap_or(("", canonical));
        let root = v.as_object_mut().expect("a table holds the alias");
        let target = if cp.is_empty() {
            root
        } else {
            let entry = root
                .entry(cp)
                .or_insert_with(|| Value::Object(Default::default()));
            match entry.as_object_mut() {
                Some(t) => t,
                None => {
                    return Err(ScenarioError::WrongType {
                        field: cp.into(),
                        expected: "a table".into(),
                        found: kind(entry).into(),
                    })
                }
            }
        };
        if target.contains_key(ck) {
            return Err(ScenarioError::Value(format!(
                "`{alias}` and `{canonical}` name the same value; give only one"
            )));
        }
        target.insert(ck.into(), value);
    }
    Ok(v)
}

impl Scenario {
    /// Reads the files a scenario refers to (a height map's CSV), relative to `dir`,
    /// when their contents are not already in the scenario.
    pub fn load_terrain_files(&mut self, dir: &Path) -> Result<(), ScenarioError> {
        if let TerrainSpec::HeightMap { file, heights, .. } = &mut self.terrain {
            if heights.is_empty() {
                *heights = read_height_csv(&dir.join(file.as_str()))?;
            }
        }
        Ok(())
    }

    /// Builds a scenario from a (possibly partial) JSON value: given fields override the
    /// defaults, unknown fields and wrongly typed values are rejected with their dotted
    /// path. Does not call [`Scenario::validate`].
    /// Keys may also be spelled as in [`ALIASES`].
    pub fn from_value(v: Value) -> Result<Scenario, ScenarioError> {
        let v = canonical_keys(v)?;
        let mut base = serde_json::to_value(Scenario::default()).expect("defaults serialise");
        merge(&mut base, v, "")?;
        // The terrain table is replaced, not merged, so serde checks it: its errors are
        // prefixed with its name.
        if let Some(t) = base.get("terrain") {
            serde_json::from_value::<TerrainSpec>(t.clone())
                .map_err(|e| ScenarioError::Value(format!("terrain: {e}")))?;
        }
        serde_json::from_value(base).map_err(|e| ScenarioError::Value(e.to_string()))
    }

    /// Parses scenario text in the given format (`"toml"` or `"json"`); missing fields take
    /// their defaults. Does not validate.
    pub fn parse(text: &str, format: &str, origin: &Path) -> Result<Scenario, ScenarioError> {
        let syntax = |message: String| ScenarioError::Syntax {
            path: origin.to_path_buf(),
            message,
        };
        let value: Value = match format {
            "toml" => {
                let t: toml::Table = toml::from_str(text).map_err(|e| syntax(e.to_string()))?;
                toml_to_json(toml::Value::Table(t), "")?
            }
            "json" => crate::strict_json::parse(text).map_err(|e| syntax(e.to_string()))?,
            _ => return Err(ScenarioError::Extension(origin.to_path_buf())),
        };
        // An empty file (or one of comments only) is most likely a mistake (a file
        // truncated, the wrong file): it would silently plan the default scenario.
        if value.as_object().is_some_and(|t| t.is_empty()) {
            return Err(syntax(
                "the file sets no value (empty); to plan the default scenario, omit --scenario"
                    .into(),
            ));
        }
        let mut s = Scenario::from_value(value)?;
        s.load_terrain_files(origin.parent().unwrap_or(Path::new(".")))?;
        Ok(s)
    }

    /// Reads a scenario file, TOML or JSON by extension, and validates it.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let format = match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("toml") => "toml",
            Some(e) if e.eq_ignore_ascii_case("json") => "json",
            _ => return Err(ScenarioError::Extension(path.to_path_buf())),
        };
        let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let s = Scenario::parse(&text, format, path)?;
        s.validate()?;
        Ok(s)
    }

    /// Applies one override `key = value`, the key a dotted path (`gap.min`, `n_step`,
    /// `start.feet.BR`, `start.feet.BR[0]`) and the value a TOML value (`2.0`, `30`,
    /// `"crawl"`, `[0, 0, 0]`; a bare word such as `crawl` is taken as text).
    /// Unknown keys are rejected with their name. Does not validate.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), ScenarioError> {
        let parsed = parse_toml_value(value.trim(), key.trim())?;
        // Build the nested patch {a: {b: {c: value}}} from the path `a.b.c` (with
        // optional trailing `[i]` for one component of a point).
        let (path, index) = match key.trim().strip_suffix(']').and_then(|k| k.split_once('[')) {
            Some((p, i)) => {
                let i: usize = i
                    .parse()
                    .map_err(|_| ScenarioError::Override(format!("{key}={value}")))?;
                (p.to_string(), Some(i))
            }
            None => (key.trim().to_string(), None),
        };
        if path.is_empty() || path.split('.').any(str::is_empty) {
            return Err(ScenarioError::Override(format!("{key}={value}")));
        }
        let mut current = serde_json::to_value(&*self).expect("scenario serialises");
        let mut leaf = parsed;
        if let Some(i) = index {
            // Patch one component: read the current array, replace element i.
            let mut arr = lookup(&current, &path)?;
            let a = arr.as_array_mut().ok_or_else(|| ScenarioError::WrongType {
                field: path.clone(),
                expected: "an array (to index with [i])".into(),
                found: "a single value".into(),
            })?;
            if i >= a.len() {
                return Err(ScenarioError::UnknownField {
                    field: format!("{path}[{i}]"),
                    known: format!("indices 0..{}", a.len()),
                });
            }
            a[i] = leaf;
            leaf = arr;
        }
        for part in path.rsplit('.') {
            let mut m = serde_json::Map::new();
            m.insert(part.to_string(), leaf);
            leaf = Value::Object(m);
        }
        merge(&mut current, leaf, "")?;
        *self = serde_json::from_value(current)
            .map_err(|e| ScenarioError::Value(format!("{key}={value}: {e}")))?;
        Ok(())
    }

    /// Applies `--set key=value` overrides in order.
    pub fn apply_overrides<S: AsRef<str>>(&mut self, overrides: &[S]) -> Result<(), ScenarioError> {
        for o in overrides {
            let o = o.as_ref();
            let (k, v) = o
                .split_once('=')
                .ok_or_else(|| ScenarioError::Override(o.to_string()))?;
            self.set(k, v)?;
        }
        Ok(())
    }
}

/// Converts TOML to JSON, rejecting what JSON cannot hold (nan, inf, dates) with the
/// field's dotted path.
fn toml_to_json(v: toml::Value, path: &str) -> Result<Value, ScenarioError> {
    Ok(match v {
        toml::Value::String(s) => Value::String(s),
        toml::Value::Integer(i) => Value::from(i),
        toml::Value::Float(f) => match serde_json::Number::from_f64(f) {
            Some(n) => Value::Number(n),
            None => {
                return Err(ScenarioError::WrongType {
                    field: path.to_string(),
                    expected: "a finite number".into(),
                    found: f.to_string(),
                })
            }
        },
        toml::Value::Boolean(b) => Value::Bool(b),
        toml::Value::Datetime(d) => {
            return Err(ScenarioError::WrongType {
                field: path.to_string(),
                expected: "a number or text".into(),
                found: format!("a date ({d})"),
            })
        }
        toml::Value::Array(a) => Value::Array(
            a.into_iter()
                .enumerate()
                .map(|(i, x)| toml_to_json(x, &format!("{path}[{i}]")))
                .collect::<Result<_, _>>()?,
        ),
        toml::Value::Table(t) => Value::Object(
            t.into_iter()
                .map(|(k, x)| {
                    let here = join(path, &k);
                    toml_to_json(x, &here).map(|j| (k, j))
                })
                .collect::<Result<_, _>>()?,
        ),
    })
}

/// Parses the value of a `--set`: a TOML value, or bare text when it is not one; a
/// number beyond f64's range (`1e400`, which TOML rejects) is an error, not text.
fn parse_toml_value(s: &str, key: &str) -> Result<Value, ScenarioError> {
    let doc = format!("v = {s}");
    match toml::from_str::<toml::Table>(&doc) {
        Ok(mut t) => match t.remove("v") {
            Some(v) => toml_to_json(v, key),
            None => Ok(Value::String(s.to_string())),
        },
        Err(_) => match s.trim().parse::<f64>() {
            Ok(f) if f.is_infinite() && s.bytes().any(|b| b.is_ascii_digit()) => {
                Err(ScenarioError::WrongType {
                    field: key.to_string(),
                    expected: "a finite number".into(),
                    found: format!("{} (beyond the range of a 64-bit float)", s.trim()),
                })
            }
            _ => Ok(Value::String(s.to_string())),
        },
    }
}

/// The value at a dotted path of `v`.
fn lookup(v: &Value, path: &str) -> Result<Value, ScenarioError> {
    let mut cur = v;
    let mut here = String::new();
    for part in path.split('.') {
        here = join(&here, part);
        cur = match cur.as_object() {
            Some(m) => m.get(part).ok_or_else(|| ScenarioError::UnknownField {
                field: here.clone(),
                known: m.keys().cloned().collect::<Vec<_>>().join(", "),
            })?,
            None => {
                return Err(ScenarioError::UnknownField {
                    field: here,
                    known: "none (not a table)".into(),
                })
            }
        };
    }
    Ok(cur.clone())
}
