//! `tspath`: the command-line front end over the library.

#[cfg(not(target_arch = "wasm32"))]
use std::process::ExitCode;

#[cfg(not(target_arch = "wasm32"))]
fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match tspath::cli::run_with_status(&args) {
        Ok((out, tspath::cli::Status::Done)) => {
            print!("{out}");
            ExitCode::SUCCESS
        }
        Ok((out, tspath::cli::Status::Problems(problems))) => {
            print!("{out}");
            eprintln!("tspath: planned with problems:");
            for p in problems {
                eprintln!("  - {p}");
            }
            ExitCode::from(tspath::cli::EXIT_PROBLEMS)
        }
        Err(e) => {
            eprintln!("tspath: {e}");
            ExitCode::from(2)
        }
    }
}

/// The command-line front end is native only; the wasm build exposes the library instead.
#[cfg(target_arch = "wasm32")]
fn main() {}
