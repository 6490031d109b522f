//! The `tidepool` binary: the command line lives in the library (`src/cli/`, feature `cli`).

fn main() -> std::process::ExitCode {
    tidepool::cli::main()
}
