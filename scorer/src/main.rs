//! `rh-score`, the ReactHuman offline scorer (specification §9–§12, §14): the command line
//! ([`cli`]) over the scorer's crates (ARCHITECTURE.md, "Code map").

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
