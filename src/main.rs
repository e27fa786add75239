//! The `delmesh` command line; see `delmesh --help` and README.md.

mod cli;
mod progress;
mod stats_json;

fn main() -> std::process::ExitCode {
    cli::main()
}
