//! How fast things run on this machine, to size a deployment: the fleet's round trip over
//! Zenoh ([`round_trip`], `gapfleet bench fleet`), the dashboard's cost per tick ([`dashboard`]), world steps ([`world`]),
//! a long run watched for growth, drift and loss ([`soak`]), and what the machine itself did
//! meanwhile ([`machine`]).

pub mod dashboard;
pub mod machine;
pub mod round_trip;
pub mod soak;
pub mod world;

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The fleet under test failed.
    #[error(transparent)]
    Demo(#[from] crate::serve::demo::DemoError),
    /// The scenario has no warehouse.
    #[error(transparent)]
    NotAWarehouse(#[from] world_sim::fleet::NotAWarehouse),
    /// The dashboard could not start.
    #[error(transparent)]
    Dashboard(#[from] dashboards::DashboardError),
    /// A Zenoh session could not be opened.
    #[error(transparent)]
    Session(#[from] fleet_net::ConfigError),
    /// The raw round trip's sessions refused a declaration or a query.
    #[error("raw round trip: {0}")]
    Raw(zenoh::Error),
    /// No raw round trip was answered.
    #[error("no raw reply came back {0}")]
    NoReply(&'static str),
    /// No free loopback port.
    #[error("no free loopback port: {0}")]
    Port(std::io::Error),
    /// The CPU-speed probe's thread could not start.
    #[error("CPU-speed probe thread: {0}")]
    Probe(std::io::Error),
    /// The raw round trip's task panicked.
    #[error("raw probe task: {0}")]
    Task(#[from] tokio::task::JoinError),
}
