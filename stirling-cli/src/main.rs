//! `stirling`: the command line of the framework (`stirling_cli::main`).

fn main() {
    stirling_cli::main()
}
