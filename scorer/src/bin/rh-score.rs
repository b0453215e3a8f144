//! `rh-score`: the ReactHuman offline scorer (specification §9–§11, §14). The command line and
//! each command live in the library ([`rh_score::cli`]).

fn main() -> std::process::ExitCode {
    rh_score::cli::main()
}
