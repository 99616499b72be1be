//! The `obbtree` command: a thin layer over the library (see `obbtree --help`).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
