//! The repository stands alone (issue 13): a clone must build, test and serve the page with
//! nothing beside it. No tracked file may name the team's shared folder next to the
//! checkout, where models and notes once were read from.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The folder beside the checkout that a clone does not have, relative and as this
/// machine spells it absolutely (spelled in pieces so that this file does not name it).
fn outside_names(root: &Path) -> Vec<String> {
    let name = ["sha", "red"].concat();
    let mut names = vec![format!("../{name}")];
    if let Some(parent) = root.parent() {
        names.push(parent.join(&name).display().to_string());
    }
    names
}

/// Tracked files (by `git ls-files`), or, outside a git checkout, every file except build
/// output and installed packages.
fn tracked_files(root: &Path) -> Vec<PathBuf> {
    let listed = Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success());
    if let Some(out) = listed {
        return out
            .stdout
            .split(|&b| b == 0)
            .filter(|p| !p.is_empty())
            .map(|p| root.join(String::from_utf8_lossy(p).as_ref()))
            .collect();
    }
    const SKIP: [&str; 7] = [
        ".git",
        "target",
        "node_modules",
        "pkg",
        "pkg-view",
        "vendor",
        "test-artifacts",
    ];
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).expect("readable folder").flatten() {
            let p = e.path();
            let skip = p
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| SKIP.contains(&n));
            if p.is_dir() && !skip {
                stack.push(p);
            } else if p.is_file() {
                out.push(p);
            }
        }
    }
    out
}

#[test]
fn no_tracked_file_reads_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = tracked_files(root);
    assert!(
        files.len() > 50,
        "found only {} files under {}",
        files.len(),
        root.display()
    );
    let names = outside_names(root);
    let mut offenders = Vec::new();
    for f in &files {
        let Ok(bytes) = std::fs::read(f) else {
            continue; // listed but deleted in the work tree
        };
        let text = String::from_utf8_lossy(&bytes);
        for (i, line) in text.lines().enumerate() {
            if names.iter().any(|n| line.contains(n.as_str())) {
                offenders.push(format!(
                    "{}:{}: {}",
                    f.strip_prefix(root).unwrap_or(f).display(),
                    i + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "these lines name a folder outside the repository (copy what they need into it):\n{}",
        offenders.join("\n")
    );
}

/// The models the tests and the page read are in the repository, with their source and
/// licence beside them.
#[test]
fn public_models_carry_their_source_and_licence() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("www/models/grapetec");
    for f in [
        "simple.tsm",
        "mouse.tsm",
        "face.tsm",
        "Bike.tsm",
        "fan.tsm",
        "gearbox2-9.tsm",
        "SOURCE.md",
        "LICENSE.LGPL-3.0",
        "COPYING.GPL-3.0",
    ] {
        let p = dir.join(f);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .len();
        assert!(len > 1000, "{} has only {len} bytes", p.display());
    }
    let source = std::fs::read_to_string(dir.join("SOURCE.md")).unwrap();
    assert!(
        source.contains("GrapeTec/T-SPLINE")
            && source.contains("0e27d75bac5f101cee8689a9e3015214db989e9d")
    );
    let lgpl = std::fs::read_to_string(dir.join("LICENSE.LGPL-3.0")).unwrap();
    assert!(lgpl.contains("GNU LESSER GENERAL PUBLIC LICENSE") && lgpl.contains("Version 3"));
}
