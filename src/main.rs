//! `lbdem` command-line entry point: parse, then hand over to the library.

fn main() -> anyhow::Result<()> {
    // SAFETY: the first statement of `main`, before any thread of this process exists.
    unsafe { lbdem::cli::refusals_without_backtraces() };
    lbdem::cli::main()
}
