//! The `timpanist` command: parse the command line and hand over to the library.

fn main() -> std::process::ExitCode {
    timpanist::cli::main()
}
