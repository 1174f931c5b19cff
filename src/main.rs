use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = rotor_twin::cli::Cli::parse();
    match rotor_twin::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
