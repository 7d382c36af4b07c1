//! `sinew completions SHELL` and `sinew man [-o DIR]`: shell completions and man pages,
//! generated from the same clap definition as `--help` (clap_complete, clap_mangen), so they
//! list every command and option the binary has.

use anyhow::{Context, Result};
use clap::{Args, CommandFactory};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

#[derive(Args, Debug)]
pub struct ManArgs {
    /// Write sinew.1 and a page per command (sinew-rig.1, sinew-export-spine.1, ...) into this
    /// folder (created if missing) instead of printing sinew.1.
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
}

/// Prints the completion script of `args.shell` on stdout.
pub fn completions(args: &CompletionsArgs) -> Result<()> {
    let mut command = super::Cli::command();
    let mut out = Vec::new();
    clap_complete::generate(args.shell, &mut command, "sinew", &mut out);
    write_stdout(&out)
}

/// Prints the man page sinew(1), or writes every page into `args.output`.
pub fn man(args: &ManArgs) -> Result<()> {
    let command = super::Cli::command();
    match &args.output {
        None => {
            let mut out = Vec::new();
            clap_mangen::Man::new(command).render(&mut out)?;
            write_stdout(&out)
        }
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("{}: cannot create folder", dir.display()))?;
            // As clap_mangen::generate_to, each page written atomically (io::write_atomic).
            let mut command = command.disable_help_subcommand(true);
            command.build();
            let mut pages = Vec::new();
            collect_pages(command, &mut pages)?;
            for (name, text) in &pages {
                let path = dir.join(name);
                sinew::io::write_atomic(&path, text)
                    .with_context(|| format!("{}: cannot write", path.display()))?;
            }
            super::out::report!("wrote {} man pages into {}", pages.len(), dir.display());
            Ok(())
        }
    }
}

/// The pages of `command` and of its commands, depth first: (file name, roff text).
fn collect_pages(command: clap::Command, pages: &mut Vec<(String, Vec<u8>)>) -> Result<()> {
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        collect_pages(sub.clone(), pages)?;
    }
    let man = clap_mangen::Man::new(command);
    let mut text = Vec::new();
    man.render(&mut text)?;
    pages.push((man.get_filename(), text));
    Ok(())
}

/// Writes `bytes` to stdout; a closed pipe (`| head`) is not an error.
fn write_stdout(bytes: &[u8]) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(bytes).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}
