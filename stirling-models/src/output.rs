//! Files written whole or not at all: every output is written to a hidden temporary file in
//! its own folder and published by one rename when complete, so an interrupted run (Ctrl-C, a
//! full disk, a crash) never leaves a file cut mid-row, and two runs writing one path never
//! interleave. Files that belong together (a record and its truth sidecar) are published
//! together, under a short lock, so that they always come from the same run.
//!
//! Without `force` a destination that exists is refused, also one that appeared while the
//! work ran: the publication is a hard link, which fails when the name is taken, so of two
//! runs racing for a new name the second gets a clear error instead of replacing the first.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why an output could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: exists; pass --force to overwrite it", .0.display())]
    Exists(PathBuf),
    #[error("{}: another run is writing it (lock {}); if none is, remove the lock", .0.display(), .1.display())]
    Locked(PathBuf, PathBuf),
    #[error("{}: is a folder, a file cannot replace it; choose another name", .0.display())]
    Folder(PathBuf),
    #[error("{}: {}", .0.display(), .1)]
    Io(PathBuf, #[source] io::Error),
}

/// A file being written: bytes go to a temporary file beside the destination.
pub struct Staged {
    dest: PathBuf,
    tmp: PathBuf,
    file: Option<BufWriter<File>>,
}

/// The temporary name of `dest`: hidden, in the same folder (so the rename stays on one file
/// system), unique to this process and moment.
fn temp_name(dest: &Path) -> PathBuf {
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    dest.with_file_name(format!(".{name}.{}.{nanos}.part", std::process::id()))
}

impl Staged {
    /// Start writing `dest` (refused up front when it exists and `force` is off).
    pub fn new(dest: &Path, force: bool) -> Result<Self, OutputError> {
        if dest.is_dir() {
            return Err(OutputError::Folder(dest.to_path_buf()));
        }
        if !force && dest.exists() {
            return Err(OutputError::Exists(dest.to_path_buf()));
        }
        let tmp = temp_name(dest);
        let io = |e| OutputError::Io(dest.to_path_buf(), e);
        let f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io)?;
        Ok(Staged {
            dest: dest.to_path_buf(),
            tmp,
            file: Some(BufWriter::new(f)),
        })
    }

    /// The destination.
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// Flush and sync the temporary file (before publishing).
    fn finish(&mut self) -> Result<(), OutputError> {
        let io = |e| OutputError::Io(self.dest.clone(), e);
        if let Some(mut f) = self.file.take() {
            f.flush().map_err(io)?;
            f.get_ref().sync_all().map_err(io)?;
        }
        Ok(())
    }

    /// Publish the file: rename over the destination (`force`), or link it to a name that
    /// must still be free.
    fn publish(&mut self, force: bool) -> Result<(), OutputError> {
        self.finish()?;
        let io = |e| OutputError::Io(self.dest.clone(), e);
        if force {
            fs::rename(&self.tmp, &self.dest).map_err(io)?;
        } else {
            match fs::hard_link(&self.tmp, &self.dest) {
                Ok(()) => {}
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                    return Err(OutputError::Exists(self.dest.clone()))
                }
                Err(e) => return Err(io(e)),
            }
            let _ = fs::remove_file(&self.tmp);
        }
        self.tmp = PathBuf::new();
        Ok(())
    }

    /// Publish this file alone.
    pub fn commit(mut self, force: bool) -> Result<(), OutputError> {
        self.publish(force)
    }
}

impl Write for Staged {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.file {
            Some(f) => f.write(buf),
            None => Err(io::Error::other("the file was already published")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match &mut self.file {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for Staged {
    /// A file never published (an error, a panic) leaves no temporary file behind.
    fn drop(&mut self) {
        if !self.tmp.as_os_str().is_empty() {
            self.file.take();
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// Publish files that belong together: under a lock on the first one's name (no other run
/// publishes to it meanwhile), every destination checked first, then each renamed or
/// linked. A run that finds the lock taken fails clearly rather than mixing its files with
/// the other run's.
pub fn commit_all(files: Vec<Staged>, force: bool) -> Result<(), OutputError> {
    let Some(first) = files.first() else {
        return Ok(());
    };
    let lock = first.dest.with_file_name(format!(
        ".{}.lock",
        first
            .dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    ));
    let held = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&lock)
        .map_err(|e| match e.kind() {
            io::ErrorKind::AlreadyExists => OutputError::Locked(first.dest.clone(), lock.clone()),
            _ => OutputError::Io(lock.clone(), e),
        })?;
    let out = publish_each(files, force);
    drop(held);
    let _ = fs::remove_file(&lock);
    out
}

fn publish_each(mut files: Vec<Staged>, force: bool) -> Result<(), OutputError> {
    // every destination checked before the first is published: the pair goes whole or not
    if let Some(f) = files.iter().find(|f| f.dest.is_dir()) {
        return Err(OutputError::Folder(f.dest.clone()));
    }
    if !force {
        if let Some(f) = files.iter().find(|f| f.dest.exists()) {
            return Err(OutputError::Exists(f.dest.clone()));
        }
    }
    for f in &mut files {
        f.publish(force)?;
    }
    Ok(())
}

/// Write `bytes` to `dest` whole or not at all.
pub fn write_atomic(dest: &Path, bytes: &[u8], force: bool) -> Result<(), OutputError> {
    let mut s = Staged::new(dest, force)?;
    s.write_all(bytes)
        .map_err(|e| OutputError::Io(dest.to_path_buf(), e))?;
    s.commit(force)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("stirling-output-{}", std::process::id()));
        fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn an_unpublished_file_leaves_nothing() {
        let d = dir().join("a");
        fs::create_dir_all(&d).unwrap();
        let dest = d.join("cut.csv");
        {
            let mut s = Staged::new(&dest, false).unwrap();
            writeln!(s, "t,x").unwrap();
        }
        assert!(!dest.exists());
        assert_eq!(
            fs::read_dir(&d).unwrap().count(),
            0,
            "no temporary file left"
        );
    }

    #[test]
    fn a_taken_name_is_refused_without_force_and_replaced_with_it() {
        let d = dir().join("b");
        fs::create_dir_all(&d).unwrap();
        let dest = d.join("f.csv");
        let s = Staged::new(&dest, false).unwrap();
        // another run takes the name while this one works
        fs::write(&dest, "theirs").unwrap();
        let e = s.commit(false).unwrap_err();
        assert!(matches!(e, OutputError::Exists(_)), "{e}");
        assert_eq!(fs::read_to_string(&dest).unwrap(), "theirs");
        write_atomic(&dest, b"ours", true).unwrap();
        assert_eq!(fs::read_to_string(&dest).unwrap(), "ours");
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
    }

    #[test]
    fn a_pair_is_published_together_or_not_at_all() {
        let d = dir().join("c");
        fs::create_dir_all(&d).unwrap();
        let (csv, side) = (d.join("r.csv"), d.join("r.csv.truth.json"));
        fs::write(&side, "old").unwrap();
        let mut a = Staged::new(&csv, false).unwrap();
        let mut b = Staged::new(&d.join("r2.json"), false).unwrap();
        a.write_all(b"1").unwrap();
        b.write_all(b"2").unwrap();
        // the pair's second destination is taken: nothing published
        let mut c = Staged::new(&side, true).unwrap();
        c.write_all(b"new").unwrap();
        let e = commit_all(vec![a, c], false).unwrap_err();
        assert!(matches!(e, OutputError::Exists(_)), "{e}");
        assert!(!csv.exists());
        assert_eq!(fs::read_to_string(&side).unwrap(), "old");
        commit_all(vec![b], false).unwrap();
        // a lock held by another run
        let lock = d.join(".r.csv.lock");
        fs::write(&lock, "").unwrap();
        let a = Staged::new(&csv, true).unwrap();
        let e = commit_all(vec![a], true).unwrap_err();
        assert!(matches!(e, OutputError::Locked(..)), "{e}");
        fs::remove_file(&lock).unwrap();
        // the sidecar's name became a folder while the run worked: nothing published, even
        // with force (it left the record without its truth file)
        let (csv2, side2) = (d.join("s.csv"), d.join("s.csv.truth.json"));
        let a = Staged::new(&csv2, true).unwrap();
        let b = Staged::new(&side2, true).unwrap();
        fs::create_dir_all(&side2).unwrap();
        let e = commit_all(vec![a, b], true).unwrap_err();
        assert!(matches!(e, OutputError::Folder(_)), "{e}");
        assert!(!csv2.exists());
        assert!(matches!(
            Staged::new(&side2, true),
            Err(OutputError::Folder(_))
        ));
    }
}
