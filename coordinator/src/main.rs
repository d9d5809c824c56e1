//! `gapfleet`: the user-facing binary. It parses the command line ([`cli`]) and runs the
//! subcommand; the work lives in the `coordinator` library (`fleet`, `bench`, `study`).

mod cli;

use clap::Parser as _;

fn main() -> anyhow::Result<()> {
    cli::Cli::parse().command.run()
}
