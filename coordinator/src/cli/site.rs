//! `gapfleet site`: a secured site's credentials and Zenoh configs.

use anyhow::Result;
use clap::Subcommand;
use coordinator::site::{SiteSpec, init};
use std::path::PathBuf;

/// `gapfleet site`'s subcommands.
#[derive(Debug, Subcommand)]
pub enum Site {
    /// Write a new site into DIR: a certificate authority, a certificate, key, user and
    /// password for the coordinator, a zenohd router, every robot and every observer, and
    /// their Zenoh configs (mutual TLS, user/password, an access-control list that lets each
    /// identity do only its part).
    Init(InitArgs),
}

/// `gapfleet site init`'s arguments.
#[derive(Debug, clap::Args)]
pub struct InitArgs {
    /// Folder to write (created; must be empty).
    dir: PathBuf,
    /// Site name (the second chunk of every key).
    #[arg(long, default_value = "demo")]
    site: schemas::Keys,
    /// Robots 0..N get an identity each.
    #[arg(long, default_value_t = 10)]
    robots: u32,
    /// Read-only observers, by name (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "dashboard,python")]
    observers: Vec<String>,
    /// Where agents, observers and a coordinator behind a router connect.
    #[arg(long, default_value = "tls/127.0.0.1:7447")]
    endpoint: String,
    /// Where the routing process listens (default: --endpoint), e.g. tls/0.0.0.0:7447.
    #[arg(long)]
    listen: Option<String>,
    /// Host names and IP addresses the router's certificate is valid for (repeatable;
    /// default: the endpoint's host, localhost and 127.0.0.1).
    #[arg(long = "host")]
    hosts: Vec<String>,
    /// Days the certificates are valid.
    #[arg(long, default_value_t = 825)]
    valid_days: u32,
}

impl Site {
    /// Runs the subcommand.
    pub fn run(self) -> Result<()> {
        match self {
            Site::Init(args) => {
                let hosts = if args.hosts.is_empty() {
                    default_hosts(&args.endpoint)
                } else {
                    args.hosts
                };
                let spec = SiteSpec {
                    keys: args.site,
                    robots: args.robots,
                    observers: args.observers,
                    endpoint: args.endpoint,
                    listen: args.listen,
                    hosts,
                    valid_days: args.valid_days,
                };
                let dir = args.dir;
                let paths = init(&dir, &spec)?;
                let d = paths.dir.display();
                let last = spec.robots - 1;
                println!(
                    "site {:?}: {} robots, observers {:?}, written to {d}\n",
                    spec.keys.site(),
                    spec.robots,
                    spec.observers
                );
                println!("The coordinator routes (the access-control list is in its config):");
                println!(
                    "  gapfleet coordinator --site {} --robots {} --zenoh-config {}",
                    spec.keys,
                    spec.robots,
                    paths.coordinator_config().display()
                );
                println!("or a zenohd router routes, and the coordinator is its client:");
                println!("  zenohd -c {}", paths.router_config().display());
                println!(
                    "  gapfleet coordinator --site {} --robots {} --zenoh-config {}",
                    spec.keys,
                    spec.robots,
                    paths.coordinator_behind_router_config().display()
                );
                println!("Robot N's agent (N = 0..{last}):");
                println!(
                    "  gapfleet-agent --site {} --robot-id N --zenoh-config {d}/robot-N/zenoh.json5",
                    spec.keys
                );
                if let Some(first) = spec.observers.first() {
                    println!("Observers read with their own config, e.g.");
                    println!("  {}", paths.observer_config(first).display());
                }
                println!(
                    "\nKeys, passwords and configs are readable by their owner only. {}/ca-key.pem\n\
                     issues identities: keep it offline. Certificates expire in {} days.",
                    d, spec.valid_days
                );
                Ok(())
            }
        }
    }
}

/// The endpoint's host, localhost and 127.0.0.1.
fn default_hosts(endpoint: &str) -> Vec<String> {
    let mut hosts = vec!["localhost".to_owned(), "127.0.0.1".to_owned()];
    if let Some((host, _)) = endpoint
        .strip_prefix("tls/")
        .and_then(|a| a.rsplit_once(':'))
    {
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if !hosts.iter().any(|h| h == host) && host != "0.0.0.0" {
            hosts.insert(0, host.to_owned());
        }
    }
    hosts
}
