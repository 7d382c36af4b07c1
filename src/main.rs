use clap::Parser;
use std::process::ExitCode;

/// Exit code for bad input (files, arguments, options): the message says which and why.
const EXIT_BAD_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = sinew::cli::Cli::parse();
    match sinew::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // `{:#}` joins the causes on one line.
            eprintln!("sinew: error: {error:#}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}
