//! Every command of the README's `sh` blocks, run as written from a fresh clone of this
//! repository, exits 0 and leaves `git status` clean (outputs go under the git-ignored
//! `out/`).
//!
//! `cadmorph` is this test's build of the binary, first on `PATH` (what `cargo install
//! --path crates/cli` puts on it). Excepted, and checked instead for what they name:
//! `bash scripts/test` (this test runs inside it), and the `cargo install` / `cargo
//! build` lines, which would build the workspace again from nothing in release mode
//! (minutes on a 2-core machine): the test checks that `--path` is the package of the
//! `cadmorph` binary and that a `--profile` exists.
//!
//! The clone is of the repository's committed `HEAD`: commit the README before running
//! this locally.

mod common;

use std::path::Path;
use std::process::Command;

use common::{root, Scratch};

/// The lines of the README's ```sh blocks, without comments and blank lines.
fn commands(readme: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in readme.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            inside = !inside && t == "```sh";
            continue;
        }
        if inside && !t.is_empty() && !t.starts_with('#') {
            out.push(t.to_owned());
        }
    }
    out
}

fn git(dir: &Path, args: &[&str]) -> String {
    let out = Command::new("git").args(args).current_dir(dir).output().expect("git runs");
    assert!(out.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// What a `cargo` line names exists in the clone.
fn check_cargo_line(clone: &Path, line: &str) {
    let words: Vec<&str> = line.split_whitespace().collect();
    match words.get(1).copied() {
        Some("install") => {
            let at = words.iter().position(|w| *w == "--path").expect("cargo install --path P");
            let manifest = std::fs::read_to_string(clone.join(words[at + 1]).join("Cargo.toml")).expect("the package");
            assert!(manifest.contains("[[bin]]\nname = \"cadmorph\""), "{line}: no cadmorph binary there");
        }
        Some("build") => {
            let manifest = std::fs::read_to_string(clone.join("Cargo.toml")).unwrap();
            if let Some(at) = words.iter().position(|w| *w == "--profile") {
                let profile = format!("[profile.{}]", words[at + 1]);
                assert!(manifest.contains(&profile), "{line}: no {profile} in Cargo.toml");
            }
            assert!(manifest.contains("[profile.release]\ndebug = false"), "release builds without debug information");
        }
        _ => panic!("{line}: a cargo line this test does not know how to check"),
    }
}

#[test]
fn every_readme_command_runs_from_a_clean_clone() {
    let s = Scratch::new("readme");
    let clone = s.dir().join("clone");
    let root = root();
    git(s.dir(), &["clone", "--quiet", "--no-hardlinks", root.to_str().unwrap(), clone.to_str().unwrap()]);
    let bin = s.dir().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_cadmorph"), bin.join("cadmorph")).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let readme = std::fs::read_to_string(clone.join("README.md")).unwrap();
    let lines = commands(&readme);
    assert!(lines.len() > 20, "the README's commands are found: {lines:?}");
    let mut ran = 0;
    for line in &lines {
        if line == "bash scripts/test" {
            continue;
        }
        if line.starts_with("cargo ") {
            check_cargo_line(&clone, line);
            continue;
        }
        let out =
            Command::new("bash").args(["-c", line]).current_dir(&clone).env("PATH", &path).output().expect("bash runs");
        assert!(
            out.status.success(),
            "README command failed ({}): {line}\n{}{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        ran += 1;
    }
    assert!(ran >= 25, "{ran} commands ran");
    let status = git(&clone, &["status", "--porcelain", "--untracked-files=all"]);
    assert!(status.is_empty(), "the README's commands left files git sees:\n{status}");
    // The outputs are there, under out/.
    assert!(clone.join("out/hull3_morphed.igs").is_file());
    assert!(clone.join("out/cadmorph.1").is_file());
}
