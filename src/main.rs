mod cli;

use clap::Parser;
use std::process::ExitCode;

/// Exit code for bad input (files, arguments, options): the message says which and why.
const EXIT_BAD_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = match cli::Cli::try_parse() {
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
    match cli::run(cli) {
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
/// arguments or the possible values it lists under it) and its tips (a similar name, how to pass
/// a negative number), without its usage block, and which help to read.
fn clap_one_line(error: &clap::Error) -> String {
    let text = error.render().to_string();
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let what: Vec<&str> = lines
        .iter()
        .copied()
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    let what = what.join(" ");
    let mut line = what.strip_prefix("error: ").unwrap_or(&what).to_string();
    let tips: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| l.starts_with("tip:"))
        .collect();
    for tip in &tips {
        line.push_str("; ");
        line.push_str(tip);
    }
    // clap suggests a subcommand only when it is close by its own measure ("rnder"); sinew's
    // finds a few more ("rgi").
    if tips.is_empty() && error.kind() == clap::error::ErrorKind::InvalidSubcommand {
        if let Some(clap::error::ContextValue::String(given)) =
            error.get(clap::error::ContextKind::InvalidSubcommand)
        {
            let suggestion = sinew::names::closest(given, cli::command_names());
            line.push_str(&sinew::names::did_you_mean(&suggestion));
        }
    }
    // "Usage: sinew rig [OPTIONS] ...": the words before the first placeholder name the command.
    let command = lines
        .iter()
        .find_map(|l| l.strip_prefix("Usage: "))
        .map(|usage| {
            usage
                .split_whitespace()
                .take_while(|w| !w.starts_with(['[', '<', '-']))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .filter(|c| !c.is_empty())
        .unwrap_or_else(|| "sinew".into());
    format!("{line} (see {command} --help)")
}
