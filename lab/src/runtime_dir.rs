//! A private `XDG_RUNTIME_DIR` for processes started without a valid one
//! (containers, CI, `sudo`, cron), set before the Vulkan loader starts.
//!
//! When the Vulkan loader initialises Mesa's drivers (lavapipe included),
//! their window-system code asks libwayland-client for a display, and
//! libwayland prints `error: XDG_RUNTIME_DIR is invalid or not set in the
//! environment.` to stderr, once per instance, whenever the variable is
//! unset or not an absolute path. Headless rendering does not need it, so
//! nothing fails, but the line reads as a failure. The tools and the render
//! tests therefore point the variable at a directory of their own before
//! creating a wgpu instance: `mrsl-runtime-<uid>` in
//! [`std::env::temp_dir`], created with mode 0700 as the XDG Base Directory
//! specification asks, and reused while it is still a directory of ours
//! that nobody else can enter. Nothing is written into it (no Wayland
//! compositor listens there); a valid variable is never changed.

use std::path::{Path, PathBuf};

/// Whether `value` is a usable `XDG_RUNTIME_DIR`: an absolute path (what
/// libwayland checks) to an existing directory.
pub fn is_valid(value: Option<&std::ffi::OsStr>) -> bool {
    value.map(Path::new).is_some_and(|p| p.is_absolute() && p.is_dir())
}

/// Sets `XDG_RUNTIME_DIR` to a private directory when it is unset or
/// invalid ([`is_valid`]); returns the directory it set, or `None` when the
/// variable was valid or no private directory could be made (then
/// everything works as before, with libwayland's line).
///
/// # Safety
///
/// It changes the process environment, so (as for
/// [`std::env::set_var`]) no other thread may be reading or writing the
/// environment meanwhile: call it at the start of `main`, before any thread
/// is started and before wgpu or the Vulkan loader is used.
pub unsafe fn ensure_xdg_runtime_dir() -> Option<PathBuf> {
    if is_valid(std::env::var_os("XDG_RUNTIME_DIR").as_deref()) {
        return None;
    }
    let dir = private_dir(&std::env::temp_dir())?;
    // SAFETY: the caller guarantees that no other thread touches the environment.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    Some(dir)
}

/// `base/mrsl-runtime-<uid>`, created with mode 0700 if missing; `None`
/// when it cannot be made or is not a directory of this user's that only
/// this user can enter (someone else may have made it first).
#[cfg(unix)]
pub fn private_dir(base: &Path) -> Option<PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    // The process's user: the owner of a file it creates. `/proc/self` would
    // be simpler but is Linux-only, and std has no getuid.
    let uid = {
        let probe = base.join(format!("mrsl-runtime-probe-{}", std::process::id()));
        std::fs::create_dir(&probe).ok()?;
        let uid = std::fs::metadata(&probe).map(|m| m.uid());
        let _ = std::fs::remove_dir(&probe);
        uid.ok()?
    };
    let dir = base.join(format!("mrsl-runtime-{uid}"));
    match std::fs::DirBuilder::new().mode(0o700).create(&dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(_) => return None,
    }
    // Not followed through a link: a link planted by another user fails here.
    let meta = std::fs::symlink_metadata(&dir).ok()?;
    (meta.is_dir() && meta.uid() == uid && meta.permissions().mode() & 0o077 == 0).then_some(dir)
}

/// Elsewhere there is no libwayland, and nothing to do.
#[cfg(not(unix))]
pub fn private_dir(_base: &Path) -> Option<PathBuf> {
    None
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    #[test]
    fn only_absolute_paths_to_directories_are_valid() {
        let tmp = std::env::temp_dir();
        assert!(is_valid(Some(tmp.as_os_str())));
        assert!(!is_valid(None));
        assert!(!is_valid(Some("".as_ref())));
        assert!(!is_valid(Some("relative/dir".as_ref())));
        assert!(!is_valid(Some(tmp.join("mrsl-no-such-dir-here").as_os_str())));
    }

    #[test]
    fn the_private_dir_is_ours_alone_and_reused() {
        let base = std::env::temp_dir().join(format!("mrsl-runtime-test-{}", std::process::id()));
        std::fs::create_dir_all(&base).unwrap();
        let dir = private_dir(&base).expect("a private directory");
        assert!(dir.starts_with(&base) && dir.is_dir());
        assert_eq!(std::fs::metadata(&dir).unwrap().permissions().mode() & 0o777, 0o700);
        assert!(is_valid(Some(dir.as_os_str())));
        assert_eq!(private_dir(&base), Some(dir.clone()), "the same directory next time");
        // Opened to others (not made by us as asked): refused, not reused.
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        assert_eq!(private_dir(&base), None);
        std::fs::remove_dir_all(&base).unwrap();
    }
}
