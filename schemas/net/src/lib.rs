//! What every gapfleet process (agents, the coordinator, the robots' hardware, benchmarks)
//! shares on the network: Zenoh session settings (a config file, or endpoints on the command
//! line, with multicast scouting off unless a config file turns it on), the shutdown signal,
//! and how rejected network input is logged.

use std::path::PathBuf;

/// How a process joins the Zenoh network.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct NetArgs {
    /// Zenoh config file (JSON5); `--connect`/`--listen` are added to it.
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Endpoint to connect to, e.g. tcp/127.0.0.1:7447 (repeatable).
    #[arg(long, value_name = "ENDPOINT")]
    pub connect: Vec<String>,
    /// Endpoint to listen on, e.g. tcp/0.0.0.0:7447 (repeatable).
    #[arg(long, value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Zenoh mode (default: the config file's, else the process's).
    #[arg(long, value_name = "MODE", value_enum)]
    pub mode: Option<Role>,
}

/// The role a session plays (Zenoh's mode): `--mode`, or the process's own when nothing else
/// says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Role {
    /// A client of a router (the coordinator's session, or `zenohd`): agents, and a
    /// coordinator behind routers. Zenoh routers do not relay between peers of one subsystem
    /// (peers are expected to mesh), so everything behind a router is a client. `open` waits
    /// until the router is there, so start order does not matter.
    Client,
    /// A coordinator: routes for small fleets.
    Router,
    /// A peer (benchmarks, tests).
    Peer,
}

impl Role {
    /// The mode's name in a Zenoh config (`mode`).
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Client => "client",
            Role::Router => "router",
            Role::Peer => "peer",
        }
    }
}

/// A Zenoh config error with the offending setting.
#[derive(Debug, thiserror::Error)]
#[error("zenoh config: {setting}: {source}")]
pub struct ConfigError {
    /// Which setting.
    pub setting: String,
    /// Zenoh's error.
    pub source: zenoh::Error,
}

fn set(config: &mut zenoh::Config, key: &str, value: &str) -> Result<(), ConfigError> {
    config.insert_json5(key, value).map_err(|e| ConfigError {
        setting: format!("{key} = {value}"),
        source: e,
    })
}

/// Publications under `gapfleet/**` are not express: Zenoh may batch them. A link's send queue
/// holds 2 batches per priority, and an express message takes a batch of its own; an agent puts
/// a command, an intent and a fan in a row, so with both cores busy a third message found no
/// batch within Zenoh's 1 ms and was dropped (100 agents at full speed, 10,000 ticks: Zenoh's
/// trace logged 20,023 drops, and 47 observations never arrived). Batched, it logged none and
/// none were lost; the round trip was as fast at 10 Hz (p99 1.18–1.39 ms either way) and faster
/// at full load (p50 5.7 ms against 9.1 ms). Batching holds a message back only while the link
/// is still sending the previous one.
/// Plain JSON (so also JSON5), as `site init` writes it into its configs too.
pub const FLEET_QOS: &str = r#"[{ "key_exprs": ["gapfleet/**"], "config": { "express": false } }]"#;

/// How long (µs) a publication waits for a free batch in a link's send queue before Zenoh drops
/// it, set on every gapfleet session. Zenoh's default, 1 ms, is shorter than a scheduling hiccup
/// on a saturated machine: with the fleet's publications batched, 100 agents at full speed on
/// two cores still lost about one observation in a million to it (110 in 10⁶ ticks; each loss
/// came 14–18 ms after a traced deadline drop). A waiting put blocks only its own task, and a
/// dead or blackholed link still drops after this wait rather than blocking for good.
pub const DROP_WAIT_US: u64 = 10_000;

const DROP_WAIT_KEY: &str = "transport/link/tx/queue/congestion_control/drop/wait_before_drop";

/// Batches (of up to 64 KiB each) in a link's send queue for the data priority, the fleet's
/// publications' (Zenoh's default 2, its maximum 16), set on every gapfleet session. Zenoh
/// drops a put only when the batch being filled is full and no other comes back from the
/// link's sender within [`DROP_WAIT_US`]; the sender of every link in a process is one thread
/// (Zenoh's TX runtime), which a saturated machine can keep off a core for tens of
/// milliseconds. With 2 batches, 100 agents at full speed on two cores lost about one
/// observation in a million that way, with 1 ms or 10 ms of wait alike; 16 batches are
/// 1 MiB of backlog per link, dozens of ticks of observations. Zenoh allocates them lazily:
/// a link that never backs up never holds more than it did.
pub const DATA_QUEUE_BATCHES: usize = 16;

const DATA_QUEUE_KEY: &str = "transport/link/tx/queue/size/data";

/// Zenoh's link lease (ms), set on every gapfleet session: a peer not heard from for this long
/// (keep-alives go 4 times a lease) is gone, its transport closed and its liveliness tokens
/// withdrawn, so a robot cut off by a partition is flagged within 3 s. (Zenoh's default is
/// 10 s.) A closed TCP connection, as when a process dies, is noticed at once.
pub const LEASE_MS: u64 = 3000;

const LEASE_KEY: &str = "transport/link/tx/lease";

/// The fleet's link settings beside the batching, as (key, value): the lease, the drop wait
/// and the data queue.
fn transport_settings() -> [(&'static str, String); 3] {
    [
        (LEASE_KEY, LEASE_MS.to_string()),
        (DROP_WAIT_KEY, DROP_WAIT_US.to_string()),
        (DATA_QUEUE_KEY, DATA_QUEUE_BATCHES.to_string()),
    ]
}

/// Whether `config` carries the fleet's transport settings: the lease, the drop wait, the data
/// queue and batched publications, as [`config`] and [`loopback`] set them and `gapfleet site
/// init` writes them. `Err` names the first that differs; [`from_file`] warns with it, since a
/// config written by hand may leave them out (Zenoh's defaults then: a 10 s lease, a 1 ms
/// wait, 2 batches, express publications).
pub fn check_fleet_settings(config: &zenoh::Config) -> Result<(), SettingDiffers> {
    let read = |key: &'static str| {
        config
            .get_json(key)
            .map_err(|source| SettingDiffers::Unreadable { key, source })
    };
    for (key, fleet) in transport_settings() {
        let value = read(key)?;
        if value != fleet {
            return Err(SettingDiffers::Value { key, value, fleet });
        }
    }
    let key = "qos/publication";
    let value = read(key)?;
    if !(value.contains("\"gapfleet/**\"") && value.contains("\"express\":false")) {
        return Err(SettingDiffers::Value {
            key,
            value,
            fleet: FLEET_QOS.to_owned(),
        });
    }
    Ok(())
}

/// The first of the fleet's transport settings a Zenoh config does not carry.
#[derive(Debug, thiserror::Error)]
pub enum SettingDiffers {
    /// The setting could not be read.
    #[error("{key}: {source}")]
    Unreadable {
        /// The setting.
        key: &'static str,
        /// Zenoh's error.
        source: zenoh::Error,
    },
    /// It has another value.
    #[error("{key} is {value}, the fleet's is {fleet}")]
    Value {
        /// The setting.
        key: &'static str,
        /// Its value in the config (JSON).
        value: String,
        /// The fleet's (JSON).
        fleet: String,
    },
}

fn json_list(items: &[String]) -> String {
    let quoted: Vec<String> = items.iter().map(|s| format!("{s:?}")).collect();
    format!("[{}]", quoted.join(","))
}

/// The Zenoh config in the JSON5 file at `path`, as written by `gapfleet site init`; a file
/// without the fleet's transport settings is taken as it is, with a warning.
pub fn from_file(path: &std::path::Path) -> Result<zenoh::Config, ConfigError> {
    let config = zenoh::Config::from_file(path).map_err(|e| ConfigError {
        setting: path.display().to_string(),
        source: e,
    })?;
    if let Err(difference) = check_fleet_settings(&config) {
        tracing::warn!(
            file = %path.display(),
            "{difference}: this Zenoh config lacks the fleet's transport settings \
             (`gapfleet site init` writes them)"
        );
    }
    Ok(config)
}

/// Zenoh's defaults with what every session gapfleet builds itself carries: `role`, multicast
/// scouting off, the fleet's batching and transport settings, and a client that keeps retrying
/// its first connection.
fn fleet_base(role: Role) -> Result<zenoh::Config, ConfigError> {
    let mut c = zenoh::Config::default();
    set(&mut c, "mode", &format!("{:?}", role.as_str()))?;
    set(&mut c, "scouting/multicast/enabled", "false")?;
    set(&mut c, "qos/publication", FLEET_QOS)?;
    for (key, value) in transport_settings() {
        set(&mut c, key, &value)?;
    }
    if role == Role::Client {
        set(&mut c, "connect/timeout_ms", "-1")?;
    }
    Ok(c)
}

/// Builds the session config: the file (if any), then mode and endpoints from the arguments.
/// Without a file, multicast scouting is off (loopback fleets and CI must not find strangers).
pub fn config(args: &NetArgs, default_role: Role) -> Result<zenoh::Config, ConfigError> {
    let mut config = match &args.zenoh_config {
        Some(path) => from_file(path)?,
        None => fleet_base(default_role)?,
    };
    if let Some(mode) = args.mode {
        set(&mut config, "mode", &format!("{:?}", mode.as_str()))?;
    }
    if !args.connect.is_empty() {
        set(&mut config, "connect/endpoints", &json_list(&args.connect))?;
    }
    if !args.listen.is_empty() {
        set(&mut config, "listen/endpoints", &json_list(&args.listen))?;
    }
    Ok(config)
}

/// A loopback-only config: `role`, multicast scouting off, listening and connecting exactly
/// where told. Used by the demo and the tests.
pub fn loopback(
    role: Role,
    listen: &[String],
    connect: &[String],
) -> Result<zenoh::Config, ConfigError> {
    let mut c = fleet_base(role)?;
    set(&mut c, "listen/endpoints", &json_list(listen))?;
    set(&mut c, "connect/endpoints", &json_list(connect))?;
    Ok(c)
}

/// Opens a loopback session at `endpoint`: a router listening there, or a client connecting
/// to it.
pub async fn open_loopback(role: Role, endpoint: &str) -> Result<zenoh::Session, ConfigError> {
    let endpoints = [endpoint.to_owned()];
    let config = match role {
        Role::Router => loopback(role, &endpoints, &[])?,
        Role::Client | Role::Peer => loopback(role, &[], &endpoints)?,
    };
    zenoh::open(config).await.map_err(|e| ConfigError {
        setting: format!("{} session on {endpoint}", role.as_str()),
        source: e,
    })
}

/// A free TCP port on 127.0.0.1 (bound and released; good enough for tests and the demo).
pub fn free_loopback_port() -> std::io::Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}

/// Completes on SIGINT or SIGTERM: the shutdown of every gapfleet process.
pub async fn shutdown_signal() {
    use tokio::signal::unix::{SignalKind, signal};
    match signal(SignalKind::terminate()) {
        Ok(mut term) => {
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = term.recv() => {}
            }
        }
        Err(_) => {
            let _ = tokio::signal::ctrl_c().await;
        }
    }
}

/// Whether the `n`-th rejected message (counting from 1) is logged: the first ten, then every
/// hundredth, so that a flood of bad messages cannot flood the log. Every gapfleet process
/// logs what it rejects this way.
pub fn log_rejection(n: u64) -> bool {
    n <= 10 || n.is_multiple_of(100)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every session gapfleet builds without a file carries the fleet's lease, drop wait, data
    /// queue and batching, whatever its role (`site init`'s files are checked in
    /// `coordinator::site`); Zenoh's own defaults do not.
    #[test]
    fn every_built_config_carries_the_fleet_settings() {
        let endpoint = ["tcp/127.0.0.1:7447".to_owned()];
        let mut built = vec![
            loopback(Role::Router, &endpoint, &[]).expect("a router config"),
            loopback(Role::Client, &[], &endpoint).expect("a client config"),
        ];
        for role in [Role::Router, Role::Peer, Role::Client] {
            built.push(config(&NetArgs::default(), role).expect("a config"));
        }
        for c in &built {
            check_fleet_settings(c).expect("the fleet's settings");
        }
        let mut c = zenoh::Config::default();
        assert_eq!(
            check_fleet_settings(&c)
                .expect_err("Zenoh's default lease")
                .to_string(),
            "transport/link/tx/lease is 10000, the fleet's is 3000"
        );
        for (key, value) in transport_settings() {
            set(&mut c, key, &value).expect("a setting");
        }
        let qos = check_fleet_settings(&c).expect_err("express publications");
        assert!(
            matches!(
                qos,
                SettingDiffers::Value {
                    key: "qos/publication",
                    ..
                }
            ),
            "{qos}"
        );
        set(&mut c, "qos/publication", FLEET_QOS).expect("a setting");
        check_fleet_settings(&c).expect("the fleet's settings");
    }
}
