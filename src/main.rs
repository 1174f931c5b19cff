use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli =
        rotor_twin::cli::Cli::parse_from(rotor_twin::cli::numbers_as_values(std::env::args_os()));
    if cli.is_filter() {
        end_quietly_on_a_closed_stdout();
    }
    match rotor_twin::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", rotor_twin::cli::error_text(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// SIGPIPE back to its default action (Rust ignores it, so that `println!` to a closed pipe
/// panics): `rotor-twin modes | head` ends quietly when `head` stops reading, as coreutils do
/// (the shell sees 128 + SIGPIPE = 141). Only for the commands that compute and print: the node's
/// sockets keep it ignored.
fn end_quietly_on_a_closed_stdout() {
    // SAFETY: called once at the start of main, before any thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
