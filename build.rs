//! Build script: on glibc Linux, links the `delmesh` binary's unwinder
//! statically instead of loading `libgcc_s.so.1` at start-up.
//!
//! Rust's standard library asks for `-lgcc_s` (the unwinder: panics,
//! backtraces). That shared library's constructor asks the processor its
//! features by `cpuid`, which traps to the hypervisor on virtual machines,
//! and loading it maps and relocates one more file: together about 0.1 ms
//! of a run (a twentieth of a small mesh's whole run). The binary instead
//! finds, first on its library path, a one-line linker script named
//! `libgcc_s.so` that reads `INPUT(-lgcc_eh)`: the same unwinder, from the
//! static archive every gcc installation has (what `gcc -static-libgcc`
//! links). Panics still unwind (dropping the guards that remove temporary
//! files), threads' panics are still caught, backtraces still print.
//!
//! Only the binary (`rustc-link-arg-bins`): the library, its tests and
//! whatever a user links it into keep the shared unwinder. Not with
//! `crt-static` (the toolchain already links `libgcc_eh` then) nor with
//! musl (no `libgcc_s` at all), and not where the linker driver does not
//! know a `libgcc_eh.a` (a toolchain without gcc's runtime): the binary
//! then loads `libgcc_s` as before.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=RUSTC_LINKER");
    let var = |name: &str| std::env::var(name).unwrap_or_default();
    let static_crt = var("CARGO_CFG_TARGET_FEATURE").split(',').any(|f| f == "crt-static");
    if var("CARGO_CFG_TARGET_OS") != "linux" || var("CARGO_CFG_TARGET_ENV") != "gnu" || static_crt {
        return;
    }
    // The linker driver names the archive's path if it has one, and the
    // bare name if not (gcc's and clang's `-print-file-name`).
    let linker = std::env::var("RUSTC_LINKER").unwrap_or_else(|_| "cc".into());
    let archive = Command::new(linker).arg("-print-file-name=libgcc_eh.a").output();
    let found = archive.is_ok_and(|out| {
        let printed = String::from_utf8_lossy(&out.stdout);
        let path = Path::new(printed.trim());
        out.status.success() && path.is_absolute() && path.exists()
    });
    if !found {
        return;
    }
    let dir = PathBuf::from(var("OUT_DIR")).join("unwinder");
    if std::fs::create_dir_all(&dir).is_err() || std::fs::write(dir.join("libgcc_s.so"), "INPUT(-lgcc_eh)\n").is_err() {
        // Nothing lost: the binary then loads the shared unwinder.
        println!("cargo:warning=could not write the unwinder's linker script; linking libgcc_s");
        return;
    }
    // The compiler driver passes the -L options it is given before its own
    // library directories, and the linker searches them in that order for
    // every -l, wherever the -l stands.
    println!("cargo:rustc-link-arg-bins=-L{}", dir.display());
}
