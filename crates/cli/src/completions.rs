//! `cadmorph completions SHELL` and `cadmorph man`: shell completions and manual pages
//! generated from the command line's own definition (clap_complete, clap_mangen), so
//! they never fall behind it.

use std::path::PathBuf;

use anyhow::{Context, Result};

/// Arguments of `completions`.
#[derive(clap::Args)]
#[command(
    after_help = "Install, for example: cadmorph completions bash > ~/.local/share/bash-completion/completions/cadmorph; \
                        cadmorph completions zsh > ~/.zfunc/_cadmorph; \
                        cadmorph completions fish > ~/.config/fish/completions/cadmorph.fish"
)]
pub struct CompletionArgs {
    /// The shell.
    shell: clap_complete::Shell,
}

/// Arguments of `man`.
#[derive(clap::Args)]
pub struct ManArgs {
    /// Write one page per command (`cadmorph.1`, `cadmorph-seams.1`, `cadmorph-ffd-fit.1`,
    /// ...) into this existing folder, instead of printing `cadmorph.1` on standard output.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
}

/// Runs `completions`: the script on standard output.
pub fn completions(a: CompletionArgs, mut cmd: clap::Command) -> Result<()> {
    let mut out = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "cadmorph", &mut out);
    print!("{}", String::from_utf8_lossy(&out));
    Ok(())
}

/// The pages of `cmd` and its subcommands, each as (file name, roff text).
fn pages(cmd: clap::Command) -> Result<Vec<(String, Vec<u8>)>> {
    let mut out = Vec::new();
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()).cloned() {
        out.extend(pages(sub)?);
    }
    let man = clap_mangen::Man::new(cmd);
    let mut bytes = Vec::new();
    man.render(&mut bytes).context("rendering a manual page")?;
    out.push((man.get_filename(), bytes));
    Ok(out)
}

/// Runs `man`: every page is rendered before any is written.
pub fn man(a: ManArgs, cmd: clap::Command) -> Result<()> {
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    match a.out_dir {
        None => {
            let mut bytes = Vec::new();
            clap_mangen::Man::new(cmd).render(&mut bytes).context("rendering the manual page")?;
            print!("{}", String::from_utf8_lossy(&bytes));
        }
        Some(dir) => {
            if !dir.is_dir() {
                anyhow::bail!("{}: not a folder (make it first); nothing written", dir.display());
            }
            let pages = pages(cmd)?;
            for (name, bytes) in &pages {
                cadmorph::model::write_atomic(&dir.join(name), bytes)?;
            }
            println!("{} manual pages written to {}", pages.len(), dir.display());
        }
    }
    Ok(())
}
