//! `tidepool completions SHELL` and `tidepool man`: generated from the clap definitions, so
//! they never drift from the real flags.

use clap::CommandFactory;

use crate::cli::args::{Cli, CompletionsArgs, ManArgs};
use crate::cli::commands::output::write_stdout;
use crate::cli::error::{Error, Result};
use crate::cli::files;

/// Prints completions for a shell.
pub fn completions(args: CompletionsArgs) -> Result<()> {
    let mut bytes = Vec::new();
    clap_complete::generate(args.shell, &mut Cli::command(), "tidepool", &mut bytes);
    write_stdout(&bytes)
}

/// Prints the main manual page, or writes every command's page into a folder.
pub fn man(args: ManArgs) -> Result<()> {
    let mut command = Cli::command().disable_help_subcommand(true);
    command.build();
    match args.out_dir {
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command).render(&mut page).map_err(Error::Stdout)?;
            write_stdout(&page)
        }
        Some(dir) => {
            if !dir.is_dir() {
                return Err(Error::arg("--out-dir", format!("{} is not a folder; create it first", dir.display())));
            }
            let mut written = Vec::new();
            write_pages(&command, &dir, &mut written)?;
            for path in written {
                println!("{}", path.display());
            }
            Ok(())
        }
    }
}

/// Writes the page of `command` and of each of its subcommands (atomically, like every file).
fn write_pages(command: &clap::Command, dir: &std::path::Path, written: &mut Vec<std::path::PathBuf>) -> Result<()> {
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub, dir, written)?;
    }
    let man = clap_mangen::Man::new(command.clone());
    let mut page = Vec::new();
    man.render(&mut page).map_err(|e| Error::io("cannot render the manual page for", man.get_filename(), e))?;
    let path = dir.join(man.get_filename());
    files::write_file(&path, &page)?;
    written.push(path);
    Ok(())
}
