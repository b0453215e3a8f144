fn main() -> std::process::ExitCode {
    rh_pipeline::cli::main()
}
