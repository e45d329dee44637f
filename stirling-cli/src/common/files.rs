//! One rule for every file the command line writes (`--out FILE`, `--plot DIR`, `--report DIR`):
//! an existing file is never overwritten without `--force`, missing folders are created, and
//! every file written is named on stderr. The checks run before the (long) computation.

use std::fs;
use std::io::Write;

use std::path::{Path, PathBuf};
use std::time::SystemTime;
use stirling_models::output::Staged;

use anyhow::{bail, Context};

use super::note;

/// Check that `path` (given with `option`) may be written, and create its parent folders.
pub fn prepare_file(path: &Path, force: bool, option: &str) -> anyhow::Result<()> {
    if path.is_dir() {
        bail!(
            "{option} {}: is a folder, expected a file name",
            path.display()
        );
    }
    if path.exists() && !force {
        bail!(
            "{option}: {} exists; pass --force to overwrite it",
            path.display()
        );
    }
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            create_dir(dir, option)?;
        }
        _ => {}
    }
    Ok(())
}

/// Check that the figures `patterns` (file names, `*` matching any text) may be written into
/// `dir`, and create it. Without `force`, any existing file matching a pattern is refused.
pub fn prepare_dir(dir: &Path, patterns: &[&str], force: bool, option: &str) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{option} {}: is a file, expected a folder", dir.display());
    }
    create_dir(dir, option)?;
    if force {
        return Ok(());
    }
    let taken = matching(dir, patterns, None)?;
    if !taken.is_empty() {
        let names: Vec<String> = taken.iter().map(|p| p.display().to_string()).collect();
        bail!(
            "{option} {}: {} already {}; pass --force to overwrite",
            dir.display(),
            names.join(", "),
            if names.len() == 1 { "exists" } else { "exist" }
        );
    }
    Ok(())
}

fn create_dir(dir: &Path, option: &str) -> anyhow::Result<()> {
    fs::create_dir_all(dir)
        .with_context(|| format!("{option}: cannot create the folder {}", dir.display()))
}

/// Open a file checked by [`prepare_file`], written whole or not at all
/// ([`stirling_models::output`]): call [`Output::done`] when complete; without `force` an
/// existing file (one that appeared meanwhile) is still refused.
pub fn create(path: &Path, force: bool, option: &str) -> anyhow::Result<Output> {
    prepare_file(path, force, option)?;
    let staged = Staged::new(path, force)
        .with_context(|| format!("{option}: cannot create {}", path.display()))?;
    Ok(Output { staged, force })
}

/// A file being written by [`create`].
pub struct Output {
    staged: Staged,
    force: bool,
}

impl Output {
    /// Publish the complete file.
    pub fn done(self) -> anyhow::Result<()> {
        let path = self.staged.dest().to_path_buf();
        self.staged
            .commit(self.force)
            .with_context(|| format!("cannot write {}", path.display()))
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.staged.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.staged.flush()
    }
}

/// Write `text` to a new file (the rule above) and name it on stderr.
pub fn write_text(path: &Path, text: &str, force: bool, option: &str) -> anyhow::Result<()> {
    let mut f = create(path, force, option)?;
    f.write_all(text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    f.done()?;
    wrote(path);
    Ok(())
}

/// Name a file written.
pub fn wrote(path: &Path) {
    note(format_args!("wrote {}", path.display()));
}

/// The files of `dir` matching `patterns`, modified at or after `since` when given, sorted.
pub fn matching(
    dir: &Path,
    patterns: &[&str],
    since: Option<SystemTime>,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let entries =
        fs::read_dir(dir).with_context(|| format!("cannot list the folder {}", dir.display()))?;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !patterns.iter().any(|p| glob(p, &name)) {
            continue;
        }
        let recent = match since {
            None => true,
            Some(t) => e
                .metadata()
                .and_then(|m| m.modified())
                .is_ok_and(|m| m >= t),
        };
        if recent && e.path().is_file() {
            out.push(e.path());
        }
    }
    out.sort();
    Ok(out)
}

/// `pattern` with at most one `*` against a file name.
fn glob(pattern: &str, name: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == name,
        Some((head, tail)) => {
            name.len() >= head.len() + tail.len() && name.starts_with(head) && name.ends_with(tail)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::glob;

    #[test]
    fn globs() {
        assert!(glob("bode.svg", "bode.svg"));
        assert!(!glob("bode.svg", "bode.svg.bak"));
        assert!(glob("stage1_*.svg", "stage1_p.svg"));
        assert!(glob("*.svg", "a.svg"));
        assert!(!glob("stage1_*.svg", "stage1.svg"));
    }
}
