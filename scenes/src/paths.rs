//! Path helpers: lexical normalisation, relative paths for saving, atomic writes.

use std::path::{Component, Path, PathBuf};

/// Removes `.` and resolves `..` lexically (no file-system access).
///
/// ```
/// use nbv_scenes::paths::normalize;
/// assert_eq!(normalize("a/./b/../c.stl".as_ref()), std::path::PathBuf::from("a/c.stl"));
/// ```
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                let last = out.components().next_back();
                match last {
                    Some(Component::Normal(_)) => {
                        out.pop();
                    }
                    Some(Component::RootDir) | Some(Component::Prefix(_)) => {}
                    _ => out.push(".."),
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// `path` expressed relative to directory `dir` (both made absolute against the current
/// directory first); the absolute path when they share no directory below the root.
///
/// ```
/// use nbv_scenes::paths::relative_to;
/// let r = relative_to("/w/assets/meshes/jug.stl".as_ref(), "/w/scenes".as_ref());
/// assert_eq!(r, std::path::PathBuf::from("../assets/meshes/jug.stl"));
/// let a = relative_to("/w/assets/jug.stl".as_ref(), "/tmp/x".as_ref());
/// assert_eq!(a, std::path::PathBuf::from("/w/assets/jug.stl"));
/// ```
pub fn relative_to(path: &Path, dir: &Path) -> PathBuf {
    let (Ok(p), Ok(d)) = (std::path::absolute(path), std::path::absolute(dir)) else {
        return path.to_path_buf();
    };
    let (p, d) = (normalize(&p), normalize(&d));
    let pc: Vec<Component<'_>> = p.components().collect();
    let dc: Vec<Component<'_>> = d.components().collect();
    let common = pc.iter().zip(&dc).take_while(|(a, b)| a == b).count();
    // Sharing only the root (or a prefix): an absolute path reads better than `../../..`.
    let shared_dirs = pc[..common]
        .iter()
        .filter(|c| matches!(c, Component::Normal(_)))
        .count();
    if shared_dirs == 0 {
        return p;
    }
    let mut out = PathBuf::new();
    for _ in common..dc.len() {
        out.push("..");
    }
    for c in &pc[common..] {
        out.push(c.as_os_str());
    }
    out
}

pub use nbv_core::atomic_file::write_atomic;
