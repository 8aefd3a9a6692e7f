//! Captures the git commit the binary is built from, for the provenance every answer carries
//! (`meta.software.commit`, the `X-Software-Commit` header, `thirdbody solve --provenance`).
//! `THIRDBODY_GIT_COMMIT` overrides it (a container build has no `.git`); without either it
//! is `unknown`.
//!
//! On Linux with glibc it also links the binary with packed relative relocations (DT_RELR,
//! glibc ≥ 2.36, binutils ≥ 2.38; older linkers ignore the flag with a warning): the loader
//! then applies the executable's 23,000 relocations from a bitmap instead of one 24-byte
//! record each, which took a fifth of a `thirdbody solve` process's CPU (BENCHMARKS.md,
//! issue 12). The executable stays position-independent, so ASLR is kept.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let output = Command::new("git").args(args).output().ok()?;
    let text = String::from_utf8(output.stdout).ok()?;
    let text = text.trim();
    (output.status.success() && !text.is_empty()).then(|| text.to_string())
}

fn main() {
    let var = |name: &str| std::env::var(name).unwrap_or_default();
    if var("CARGO_CFG_TARGET_OS") == "linux" && var("CARGO_CFG_TARGET_ENV") == "gnu" {
        println!("cargo:rustc-link-arg-bins=-Wl,-z,pack-relative-relocs");
    }
    println!("cargo:rerun-if-env-changed=THIRDBODY_GIT_COMMIT");
    let commit = std::env::var("THIRDBODY_GIT_COMMIT")
        .ok()
        .filter(|c| !c.trim().is_empty())
        .or_else(|| git(&["rev-parse", "--short=12", "HEAD"]))
        .unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=THIRDBODY_GIT_COMMIT={commit}");
    // Build again when HEAD moves: a checkout changes HEAD, a commit changes its branch.
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        println!("cargo:rerun-if-changed={dir}/HEAD");
    }
    if let (Some(common), Some(branch)) = (
        git(&["rev-parse", "--git-common-dir"]),
        git(&["symbolic-ref", "-q", "HEAD"]),
    ) {
        // Only the files there are: cargo takes a file missing (a clone without packed
        // refs, as CI's fresh one) for one changed, and built the crate again every time.
        for file in [
            format!("{common}/{branch}"),
            format!("{common}/packed-refs"),
        ] {
            if std::path::Path::new(&file).exists() {
                println!("cargo:rerun-if-changed={file}");
            }
        }
    }
}
