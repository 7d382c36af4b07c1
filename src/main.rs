use clap::Parser;

use std::process::ExitCode;

/// Exit code for bad input (files, arguments, options): the message says which and why.
const EXIT_BAD_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = match sinew::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version: clap's own text, exit 0.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            // A bare `sinew`: the help, as a usage error.
            let _ = e.print();
            return ExitCode::from(EXIT_BAD_INPUT);
        }
        Err(e) => {
            eprintln!("sinew: error: {}", clap_one_line(&e));
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
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

/// A command-line error on one line: clap's first paragraph (what is wrong, with the missing
/// arguments or the possible values it lists under it), without its tips and usage block, and
/// where to look for the rest.
fn clap_one_line(error: &clap::Error) -> String {
    let text = error.render().to_string();
    let what: Vec<&str> = text
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    let what = what.join(" ");
    let what = what.strip_prefix("error: ").unwrap_or(&what);
    format!("{what} (see sinew --help)")
}
