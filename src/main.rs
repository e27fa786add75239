//! The `delmesh` command line; see `delmesh --help` and README.md.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
