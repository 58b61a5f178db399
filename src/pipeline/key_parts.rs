//! What a resumable run's key was made from, kept beside the key in its working directory, so
//! a refused `--resume` can say what changed (the code, which parameter, which input file)
//! instead of only that something did.

use crate::contract::{InputHash, code_version};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;

/// The file in a resumable stage's working directory that holds its [`KeyParts`].
pub const KEY_PARTS_FILE: &str = "run.key.json";

/// What a stage's key is made of: [`KeyParts::key`] hashes these and nothing else, so the key
/// and the account of what changed cannot drift apart.
#[derive(Debug, Serialize, Deserialize)]
pub struct KeyParts {
    pub code_version: String,
    pub kind: String,
    pub params: serde_json::Value,
    pub inputs: Vec<InputHash>,
}

impl KeyParts {
    pub fn now(kind: &str, params: &serde_json::Value, inputs: &[InputHash]) -> Self {
        Self {
            code_version: code_version(),
            kind: kind.to_string(),
            params: params.clone(),
            inputs: inputs.to_vec(),
        }
    }

    /// SHA-256 of the code version, kind and parameters (each closed by a zero byte) and the
    /// inputs' hashes in path order: the run key and the cache key.
    pub fn key(&self) -> String {
        let mut h = Sha256::new();
        for part in [self.code_version.as_str(), &self.kind, &self.params.to_string()] {
            h.update(part.as_bytes());
            h.update([0]);
        }
        let mut sorted: Vec<&InputHash> = self.inputs.iter().collect();
        sorted.sort_by(|a, b| a.path.cmp(&b.path));
        for i in sorted {
            h.update(i.sha256.as_bytes());
        }
        hex::encode(h.finalize())
    }

    /// What differs from `self` (the interrupted run's parts) in `now`, one phrase each, at
    /// most `max` (and how many more).
    pub fn changes(&self, now: &KeyParts, max: usize) -> Vec<String> {
        let mut out = Vec::new();
        if self.code_version != now.code_version {
            out.push(format!(
                "the code (run with {}, now {})",
                self.code_version, now.code_version
            ));
        }
        if self.kind != now.kind {
            out.push(format!("the stage kind ({} → {})", self.kind, now.kind));
        }
        let mut params = Vec::new();
        diff_json("", &self.params, &now.params, &mut params);
        out.extend(params);
        let was: BTreeMap<_, _> = self.inputs.iter().map(|i| (&i.path, &i.sha256)).collect();
        let is: BTreeMap<_, _> = now.inputs.iter().map(|i| (&i.path, &i.sha256)).collect();
        for (path, sha) in &was {
            match is.get(path) {
                None => out.push(format!("input {} is no longer read", path.display())),
                Some(s) if s != sha => out.push(format!("input {} changed", path.display())),
                _ => {}
            }
        }
        for path in is.keys().filter(|p| !was.contains_key(*p)) {
            out.push(format!("input {} is new", path.display()));
        }
        if out.len() > max {
            let more = out.len() - max;
            out.truncate(max);
            out.push(format!("{more} more"));
        }
        out
    }
}

/// Every leaf where `a` and `b` differ, as `path: old → new`.
fn diff_json(path: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
    use serde_json::Value::Object;
    match (a, b) {
        (Object(x), Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                match (x.get(k), y.get(k)) {
                    (Some(u), Some(v)) => diff_json(&p, u, v, out),
                    (Some(u), None) => out.push(format!("parameter {p} ({u} → unset)")),
                    (None, Some(v)) => out.push(format!("parameter {p} (unset → {v})")),
                    (None, None) => {}
                }
            }
        }
        _ if a != b => out.push(format!("parameter {path} ({a} → {b})")),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn input(path: &str, sha: &str) -> InputHash {
        InputHash {
            path: PathBuf::from(path),
            sha256: sha.into(),
            bytes: 1,
        }
    }

    #[test]
    fn the_changes_name_the_parameter_the_input_and_the_code() {
        let old = KeyParts {
            code_version: "0.1.0 (aaa)".into(),
            kind: "simulate".into(),
            params: serde_json::json!({"scene": "s.toml", "set": {"run.time": 1.0, "dem.dt": 2e-6}}),
            inputs: vec![input("s.toml", "1"), input("grains.csv", "2")],
        };
        let same = KeyParts {
            code_version: old.code_version.clone(),
            kind: old.kind.clone(),
            params: old.params.clone(),
            inputs: old.inputs.clone(),
        };
        assert!(old.changes(&same, 10).is_empty());
        let now = KeyParts {
            code_version: "0.1.0 (bbb)".into(),
            kind: "simulate".into(),
            params: serde_json::json!({"scene": "s.toml", "set": {"run.time": 2.0}}),
            inputs: vec![input("s.toml", "9"), input("more.csv", "3")],
        };
        let c = old.changes(&now, 10);
        assert_eq!(
            c,
            [
                "the code (run with 0.1.0 (aaa), now 0.1.0 (bbb))",
                "parameter set.dem.dt (2e-6 → unset)",
                "parameter set.run.time (1.0 → 2.0)",
                "input grains.csv is no longer read",
                "input s.toml changed",
                "input more.csv is new",
            ]
        );
        assert_eq!(old.changes(&now, 2).last().unwrap(), "4 more");
    }
}
