//! The `obbtree` command: a thin layer over the library (see `obbtree --help`).
// The same no-panic lints as the library: arguments and files are foreign data.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented,
        clippy::indexing_slicing,
        clippy::string_slice,
        clippy::unwrap_in_result
    )
)]

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
