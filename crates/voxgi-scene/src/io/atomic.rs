//! Writing output files so that a failure leaves nothing half-written: the content goes to a
//! temporary file beside the target, is flushed to the disk and renamed over the target, so a
//! reader sees either the old file or the whole new one. Every I/O error is returned; a full
//! disk, a vanished directory or a read-only target is an error, never a truncated file.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `path` through `write`, which gets a buffered file to write into. See [`replace`].
pub fn replace_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    replace(path, |to| {
        let mut w = BufWriter::new(File::create(to)?);
        write(&mut w)?;
        // A BufWriter flushes on drop and forgets the error: flush here to see it.
        w.flush()
    })
}

/// Writes `path` through `write`, which gets the path to write to (for encoders that open the
/// file themselves). A regular file (new or existing, also through a symbolic link) is written
/// beside and renamed into place after an fsync, keeping an existing file's permissions; if
/// anything fails the temporary file is removed and an existing file is left as it was. A
/// read-only file is an error. A device, a pipe or a path under `/dev` or `/proc`
/// (`/dev/stdout`, which may lead to a redirected file) is written in place, its errors
/// returned all the same.
pub fn replace(path: &Path, write: impl FnOnce(&Path) -> io::Result<()>) -> io::Result<()> {
    if path.starts_with("/dev") || path.starts_with("/proc") {
        return write(path);
    }
    let target = resolve_links(path);
    let existing = fs::metadata(&target).ok();
    match &existing {
        Some(m) if m.is_dir() => {
            return Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "is a directory",
            ));
        }
        Some(m) if !m.is_file() => return write(&target),
        Some(m) if m.permissions().readonly() => {
            return Err(io::Error::new(
                io::ErrorKind::PermissionDenied,
                "the file is read-only",
            ));
        }
        _ => {}
    }
    let temp = temp_beside(&target);
    let result = write(&temp).and_then(|()| {
        let f = fs::OpenOptions::new().write(true).open(&temp)?;
        if let Some(m) = &existing {
            f.set_permissions(m.permissions())?;
        }
        f.sync_all()?;
        fs::rename(&temp, &target)?;
        // The rename itself lasts once the directory is on the disk (best effort: not every
        // platform opens directories).
        if let Some(dir) = target.parent().and_then(|d| File::open(d).ok()) {
            let _ = dir.sync_all();
        }
        Ok(())
    });
    if result.is_err() {
        let _ = fs::remove_file(&temp);
    }
    result
}

/// The file `path` names once symbolic links are followed, also when the last link dangles
/// (then the file it would point to, which the write creates).
fn resolve_links(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    let mut p = path.to_path_buf();
    // A chain of links, bounded as the kernel bounds it.
    for _ in 0..40 {
        match fs::read_link(&p) {
            Ok(to) => p = p.parent().unwrap_or(Path::new(".")).join(to),
            Err(_) => break,
        }
    }
    p
}

/// A name in the target's directory that no other writer uses: hidden, with the process id
/// and a per-process counter, so two processes (or threads) writing one path never share it.
fn temp_beside(target: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = target
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    target.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("voxgi-atomic-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let d = dir("fail");
        let p = d.join("out.png");
        fs::write(&p, b"old").unwrap();
        let err = replace_with(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("encoder failed"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "encoder failed");
        assert_eq!(fs::read(&p).unwrap(), b"old");
        assert_eq!(entries(&d), ["out.png"]);
        fs::remove_dir_all(d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_write_replaces_the_file_a_link_points_to() {
        let d = dir("link");
        let real = d.join("real.exr");
        fs::write(&real, b"old").unwrap();
        let link = d.join("link.exr");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        replace_with(&link, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read(&real).unwrap(), b"new");
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(entries(&d), ["link.exr", "real.exr"]);
        fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn a_full_device_is_an_error() {
        // /dev/full accepts the open and fails every write with ENOSPC, as a full disk does.
        if !Path::new("/dev/full").exists() {
            return;
        }
        let err = replace_with(Path::new("/dev/full"), |w| w.write_all(&[0; 100_000])).unwrap_err();
        assert_eq!(err.raw_os_error(), Some(28), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_dangling_link_creates_its_target_and_permissions_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("dangling");
        let link = d.join("link.png");
        std::os::unix::fs::symlink(d.join("made.png"), &link).unwrap();
        replace_with(&link, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read(d.join("made.png")).unwrap(), b"new");
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );

        let private = d.join("private.exr");
        fs::write(&private, b"old").unwrap();
        fs::set_permissions(&private, fs::Permissions::from_mode(0o600)).unwrap();
        replace_with(&private, |w| w.write_all(b"new")).unwrap();
        let mode = fs::metadata(&private).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);

        // Read-only: refused (even for root, who could write it), the file as it was.
        fs::set_permissions(&private, fs::Permissions::from_mode(0o444)).unwrap();
        let e = replace_with(&private, |w| w.write_all(b"newer")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::PermissionDenied);
        assert_eq!(fs::read(&private).unwrap(), b"new");
        fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn a_directory_or_a_missing_directory_is_an_error() {
        let d = dir("dirs");
        assert!(replace_with(&d, |w| w.write_all(b"x")).is_err());
        assert!(replace_with(&d.join("no/such/out.png"), |w| w.write_all(b"x")).is_err());
        assert!(entries(&d).is_empty());
        fs::remove_dir_all(d).unwrap();
    }
}
