//! `lbdem` command-line entry point: parse, then hand over to the library.

fn main() -> anyhow::Result<()> {
    lbdem::cli::main()
}
