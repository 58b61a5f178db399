//! `lbdem` command-line entry point: parse, then hand over to the library.

fn main() -> anyhow::Result<()> {
    // A refused run is a message for the user, not a crash: without this, RUST_BACKTRACE=1 (set
    // in many Rust developers' shells) makes anyhow capture and print a stack backtrace under
    // every refusal. Panics still follow RUST_BACKTRACE; RUST_LIB_BACKTRACE=1 brings the error
    // backtraces back for whoever wants them.
    if std::env::var_os("RUST_LIB_BACKTRACE").is_none() {
        // SAFETY: the first statement of `main`, before any thread of this process exists.
        unsafe { std::env::set_var("RUST_LIB_BACKTRACE", "0") };
    }
    lbdem::cli::main()
}
