//! The `obbtree` command: a thin layer over the library (see `obbtree --help`).
// Arguments and files are foreign data: the no-panic lints of Cargo.toml's
// `[lints.clippy]` apply here as to the library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
