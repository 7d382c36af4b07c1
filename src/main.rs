use clap::Parser;
use std::process::ExitCode;

/// Exit code for bad input (files, arguments, options): the message says which and why.
const EXIT_BAD_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = sinew::cli::Cli::parse();
    match sinew::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("sinew: error: {}", one_line(&error));
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

/// The error and its causes on one line, leaving out a cause whose text a message before it
/// already quotes (library errors carry their source's text in their own message).
fn one_line(error: &anyhow::Error) -> String {
    let mut line = error.to_string();
    for cause in error.chain().skip(1) {
        let text = cause.to_string();
        if !line.contains(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    line.replace('\n', " ")
}
