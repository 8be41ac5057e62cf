//! Writing output files all or nothing.
//!
//! A run writes several files into one directory (`solution.json`, `plan.svg`, ...).
//! [`write_all`] writes every file to a temporary name in that directory first, then
//! renames them into place, keeping the previous version of each target aside until
//! all renames succeeded: when anything fails (a full disk, a target that is a
//! directory, no permission) the directory is left as it was and the temporary files
//! are removed, so a failed run never leaves a half-written output or a mix of old and
//! new files. [`write_atomic`] does the same for one file.
use std::path::{Path, PathBuf};

/// A failed output write: the file concerned and the I/O error.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {source}")]
pub struct OutputError {
    /// The file (or directory) that could not be written.
    pub path: PathBuf,
    /// The I/O error.
    pub source: std::io::Error,
}

fn err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError {
        path: path.to_path_buf(),
        source,
    }
}

/// A sibling of `path` named `.NAME.PID.SUFFIX` (hidden, unique to this process).
fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{suffix}", std::process::id()))
}

/// Writes one file atomically: a temporary file in the same directory, renamed into
/// place (a failed write leaves the previous file, if any, untouched).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = sibling(path, "tmp");
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Removes the regular files `names` from `dir` where they exist; returns the names
/// removed (a file that cannot be removed is left, and not listed).
pub fn remove_files<'a>(dir: &Path, names: &[&'a str]) -> Vec<&'a str> {
    names
        .iter()
        .copied()
        .filter(|n| {
            let p = dir.join(n);
            std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file())
                && std::fs::remove_file(&p).is_ok()
        })
        .collect()
}

/// Writes `files` (name, content) into `dir` (created if missing), all or nothing (see
/// the module docs). Returns the paths written, in order.
pub fn write_all(dir: &Path, files: &[(&str, &[u8])]) -> Result<Vec<PathBuf>, OutputError> {
    std::fs::create_dir_all(dir).map_err(err(dir))?;
    let targets: Vec<PathBuf> = files.iter().map(|(n, _)| dir.join(n)).collect();
    // A target that exists but is not a file (a directory) cannot be replaced by one.
    for t in &targets {
        if let Ok(m) = std::fs::symlink_metadata(t) {
            if !m.is_file() {
                return Err(OutputError {
                    path: t.clone(),
                    source: std::io::Error::other("exists and is not a regular file"),
                });
            }
        }
    }
    let temps: Vec<PathBuf> = targets.iter().map(|t| sibling(t, "tmp")).collect();
    for (k, (_, bytes)) in files.iter().enumerate() {
        if let Err(e) = std::fs::write(&temps[k], bytes) {
            remove_all(&temps[..=k]);
            return Err(err(&temps[k])(e));
        }
    }
    // Move each old target aside, then the new file in; undo everything on a failure.
    let mut backups: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (k, t) in targets.iter().enumerate() {
        let step = (|| {
            if t.exists() {
                let b = sibling(t, "bak");
                std::fs::rename(t, &b)?;
                backups.push((t.clone(), b));
            }
            std::fs::rename(&temps[k], t)
        })();
        if let Err(e) = step {
            remove_all(&targets[..k]);
            for (orig, b) in &backups {
                let _ = std::fs::rename(b, orig);
            }
            remove_all(&temps[k..]);
            return Err(err(t)(e));
        }
    }
    for (_, b) in &backups {
        let _ = std::fs::remove_file(b);
    }
    Ok(targets)
}

fn remove_all(paths: &[PathBuf]) {
    for p in paths {
        let _ = std::fs::remove_file(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<(String, String)> {
        let mut v: Vec<(String, String)> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                let content = std::fs::read_to_string(e.path()).unwrap_or_else(|_| "<dir>".into());
                (e.file_name().to_string_lossy().into_owned(), content)
            })
            .collect();
        v.sort();
        v
    }

    #[test]
    fn all_or_nothing() {
        let dir = std::env::temp_dir().join(format!("gap_output_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        write_all(&dir, &[("a.txt", b"old a"), ("b.txt", b"old b")]).unwrap();
        let before = listing(&dir);
        // A target that is a directory: nothing changes, no temporary file is left.
        std::fs::create_dir(dir.join("c.txt")).unwrap();
        let before_c = listing(&dir);
        let e = write_all(
            &dir,
            &[
                ("a.txt", b"new a"),
                ("b.txt", b"new b"),
                ("c.txt", b"new c"),
            ],
        )
        .unwrap_err();
        assert!(e.to_string().contains("c.txt"), "{e}");
        assert_eq!(listing(&dir), before_c);
        std::fs::remove_dir(dir.join("c.txt")).unwrap();
        assert_eq!(listing(&dir), before);
        // Success replaces every file.
        write_all(&dir, &[("a.txt", b"new a"), ("b.txt", b"new b")]).unwrap();
        assert_eq!(
            listing(&dir),
            vec![
                ("a.txt".into(), "new a".into()),
                ("b.txt".into(), "new b".into())
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
