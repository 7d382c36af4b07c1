//! The "Examples:" shown after each command's help. Each line is a command that runs on the
//! bundled character (`sinew demo` writes `out/character.json`) or on the reader's own art;
//! the tests below parse every one with the real argument parser.

/// `sinew` itself.
pub const SINEW: &str = "Examples:
  sinew demo                                  # rig and animate the bundled character into out/
  sinew auto art.psd -o out/art               # your layered file: rig, motion, GIFs, Spine export
  sinew edit out/character.json               # pose, key and save (Ctrl+S) in the editor
  sinew help render                           # the options of one command";

pub const RIG: &str = "Examples:
  sinew rig art.psd --handles handles.json -o rig.json --preview mesh.png
  sinew rig body.png arm.png head.png -o rig.json       # PNG layers, back to front, no weights
  sinew rig sprite.png --handles handles.json --detail coarse -o rig.json   # fewer vertices";

pub const POSE: &str = "Examples:
  sinew pose out/character.json -o rest.png
  sinew pose out/character.json --anim walk --time 0.4 -o walk.png --vertices walk.json
  sinew pose out/character.json --pose pose.json --skin pail -o pail.png";

pub const RENDER: &str = "Examples:
  sinew render out/character.json --anim walk -o walk.gif
  sinew render out/character.json --anim wave -o wave/ --fps 60        # numbered PNGs
  sinew render out/character.json --anim walk -o sheet.png --size 256x256   # sprite sheet";

pub const DEMO: &str = "Examples:
  sinew demo                      # into out/
  sinew demo -o my-out --assets my-character/          # a character laid out as the bundled one";

pub const EXPORT: &str = "Examples:
  sinew export spine out/character.json -o spine/
  sinew export gltf out/character.json -o character.glb
  sinew export dragonbones out/character.json -o db/";

pub const EXPORT_SPINE: &str = "Examples:
  sinew export spine out/character.json -o spine/                 # Spine 4.2, every vertex
  sinew export spine out/character.json -o spine/ --preset game   # decimated, 4 influences
  sinew export spine out/character.json -o spine41/ --spine-version 4.1";

pub const EXPORT_GLTF: &str = "Examples:
  sinew export gltf out/character.json -o character.glb
  sinew export gltf out/character.json -o character.glb --fps 60 --px-per-unit 200";

pub const EXPORT_DRAGONBONES: &str = "Examples:
  sinew export dragonbones out/character.json -o db/
  sinew export dragonbones out/character.json -o db/ --name hero --fps 24";

pub const AUTORIG: &str = "Examples:
  sinew autorig art.psd -o handles.json --preview proposal.png
  sinew autorig sprite.png -o handles.json --template humanoid --bones 14
  sinew autorig sprite.png -o handles.json --cage 16 --points 4";

pub const ANIMATE: &str = "Examples:
  sinew animate out/character.json --motion walk
  sinew animate out/character.json --motion run --in-place --name run_loop
  sinew animate rig.json --motion capture.bvh --map joints.json --view front";

pub const AUTO: &str = "Examples:
  sinew auto art.psd -o out/art
  sinew auto sprite.png -o out/sprite --fps 24 --render-size 256";

pub const TARGET: &str = "Examples:
  sinew target out/character.json                 # which runtime the rig plays as
  sinew target out/character.json dragonbones     # pose, render, edit as DragonBones plays
  sinew target out/character.json none            # play exactly again";

pub const COLORIZE: &str = "Examples:
  sinew colorize lineart.png --scribbles scribbles.png -o colored.png
  sinew colorize lineart.png --scribbles strokes.json -o colored.png --layers masks/ --fill soft";

pub const BATCH: &str = "Examples:
  sinew batch game.json                       # every job of the manifest, one per core
  sinew batch game.json --jobs 2
  sinew batch game.json --ray 127.0.0.1:6379 --ray-python venv/bin/python";

pub const SCHEMA: &str = "Examples:
  sinew schema handles > handles.schema.json
  sinew schema rig";

#[cfg(feature = "editor")]
pub const EDIT: &str = "Examples:
  sinew edit                                  # an empty document: drop PNG layers on it
  sinew edit out/character.json --mode animate
  sinew edit --mode colorize --line-art lineart.png";

pub const COMPLETIONS: &str = "Examples:
  sinew completions bash > ~/.local/share/bash-completion/completions/sinew
  sinew completions zsh > ~/.zfunc/_sinew        # with fpath+=~/.zfunc in ~/.zshrc
  sinew completions fish > ~/.config/fish/completions/sinew.fish";

pub const MAN: &str = "Examples:
  sinew man | man -l -                          # read it now
  sinew man -o ~/.local/share/man/man1          # install it: man sinew, man sinew-rig";

#[cfg(test)]
mod tests {
    use super::super::Cli;
    use clap::{CommandFactory, Parser};

    /// Every example line of every command's help, as the words a shell would pass.
    fn example_lines() -> Vec<(String, Vec<String>)> {
        let mut found = Vec::new();
        let mut queue = vec![Cli::command()];
        while let Some(command) = queue.pop() {
            let name = command.get_name().to_string();
            if let Some(after) = command.get_after_help() {
                for line in after.to_string().lines() {
                    let line = line.split(" #").next().unwrap_or_default();
                    let line = line.split(" >").next().unwrap_or_default();
                    let line = line.split(" |").next().unwrap_or_default();
                    let words: Vec<String> = line.split_whitespace().map(String::from).collect();
                    if words.first().is_some_and(|w| w == "sinew") {
                        found.push((name.clone(), words));
                    }
                }
            }
            queue.extend(command.get_subcommands().cloned());
        }
        found
    }

    #[test]
    fn every_command_has_examples_and_every_example_parses() {
        let lines = example_lines();
        let mut commands = vec![Cli::command()];
        let mut without = Vec::new();
        while let Some(command) = commands.pop() {
            if command.get_name() != "help" && command.get_after_help().is_none() {
                without.push(command.get_name().to_string());
            }
            commands.extend(command.get_subcommands().cloned());
        }
        assert!(without.is_empty(), "commands without examples: {without:?}");
        assert!(lines.len() > 30, "{} example lines", lines.len());
        for (command, words) in lines {
            match Cli::try_parse_from(&words) {
                Ok(_) => {}
                // `sinew help render` prints a help, as clap's "error" of that kind.
                Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelp => {}
                Err(e) => panic!("{command}: {} does not parse: {e}", words.join(" ")),
            }
        }
    }
}
