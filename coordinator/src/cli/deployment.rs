//! `gapfleet loop`: the deployment topology on one machine. A real `zenohd`, the robots'
//! hardware (`gapfleet hardware`), one agent per robot in ROS mode (`gapfleet-agent --ros
//! --robot-id`) and a coordinator that simulates nothing (`gapfleet coordinator --live all
//! --humans 0`), each its own process, as on a site.

use super::{SiteArgs, positive, speed};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// `gapfleet loop`'s arguments.
#[derive(Debug, clap::Args)]
pub struct LoopArgs {
    #[command(flatten)]
    site_args: SiteArgs,
    /// Simulated seconds the coordinator runs.
    #[arg(long, default_value_t = 300.0, value_parser = positive)]
    seconds: f64,
    /// Simulated seconds per wall second, in [0.001, 1000] (every process runs at it).
    #[arg(long, default_value_t = 1.0, value_parser = speed)]
    speed: f64,
    /// The agents' planner stack.
    #[arg(long, default_value = agent::planner::PlannerSpec::FLEET)]
    planner: agent::planner::PlannerSpec,
    /// The `zenohd` to route through (1.10.2; `bash tests/run.sh` installs one).
    #[arg(long, default_value = "zenohd")]
    zenohd: PathBuf,
    /// The coordinator's journal (`gapfleet replay DIR` re-runs it).
    #[arg(long, value_name = "DIR")]
    state: Option<PathBuf>,
    /// Save the coordinator's dashboard to this .rrd file.
    #[arg(long, value_name = "PATH")]
    rrd: Option<PathBuf>,
    /// Where the processes' logs go (default: a new folder under the system's temporary one).
    #[arg(long, value_name = "DIR")]
    logs: Option<PathBuf>,
}

/// A child process, interrupted (SIGINT, then killed after 5 s) when dropped.
struct Process {
    name: String,
    child: Child,
}

impl Process {
    fn spawn(name: impl Into<String>, command: &mut Command, log: &Path) -> Result<Self> {
        let name = name.into();
        let file = std::fs::File::create(log).with_context(|| format!("{}", log.display()))?;
        let child = command
            .stdin(Stdio::null())
            .stdout(file.try_clone()?)
            .stderr(file)
            .spawn()
            .with_context(|| format!("starting {name} ({:?})", command.get_program()))?;
        Ok(Self { name, child })
    }

    fn interrupt(&mut self) {
        let _ = Command::new("kill")
            .args(["-INT", &self.child.id().to_string()])
            .status();
    }

    fn stop(&mut self) {
        if self.child.try_wait().ok().flatten().is_some() {
            return;
        }
        self.interrupt();
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(5) {
            if self.child.try_wait().ok().flatten().is_some() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        tracing::warn!("{} did not stop on SIGINT: killed", self.name);
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Robot `robot`'s agent: in ROS mode in the robot's namespace, with the site's people's
/// radius (people_msgs carries no size, and a thinner person is yielded to less).
fn agent_command(
    agent_exe: &Path,
    robot: usize,
    planner: &str,
    endpoint: &str,
    person_radius: f64,
) -> Command {
    let mut cmd = Command::new(agent_exe);
    cmd.args(["--robot-id", &robot.to_string(), "--ros", "--namespace"])
        .arg(format!("/robot{robot}"))
        .args(["--person-radius", &person_radius.to_string()])
        .args(["--planner", planner, "--connect", endpoint])
        .env("RUST_LOG", "warn");
    cmd
}

/// The lines of `log` from the last that starts with `prefix` on.
fn last_lines(log: &Path, prefix: &str) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    let from = lines
        .iter()
        .rposition(|l| l.starts_with(prefix))
        .unwrap_or(lines.len().saturating_sub(3));
    lines[from..].join("\n")
}

impl LoopArgs {
    /// Runs the loop until the coordinator's time is up, then stops the rest.
    pub fn run(self) -> Result<()> {
        let me = std::env::current_exe().context("where gapfleet is")?;
        let agent_exe = me.with_file_name("gapfleet-agent");
        if !agent_exe.exists() {
            bail!(
                "{} is missing: build it with `cargo build --release -p agent`",
                agent_exe.display()
            );
        }
        let zenohd_ok = Command::new(&self.zenohd)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !zenohd_ok {
            bail!(
                "{} does not run: give --zenohd PATH (zenohd 1.10.2; `bash tests/run.sh` installs one)",
                self.zenohd.display()
            );
        }
        let scenario = self.site_args.scenario()?;
        let (robots, _) = scenario
            .fleet_size()
            .context("the scenario is no fleet site")?;
        let logs = match &self.logs {
            Some(dir) => {
                std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
                dir.clone()
            }
            None => tempfile::Builder::new()
                .prefix("gapfleet-loop-")
                .tempdir()?
                .keep(),
        };
        let port = fleet_net::free_loopback_port().context("a free port")?;
        let endpoint = format!("tcp/127.0.0.1:{port}");
        eprintln!(
            "gapfleet loop: zenohd on {endpoint}, hardware, {robots} agents and a coordinator of \
             real robots; logs in {}",
            logs.display()
        );
        let _zenohd = Process::spawn(
            "zenohd",
            Command::new(&self.zenohd).args(["-l", &endpoint, "--no-multicast-scouting"]),
            &logs.join("zenohd.log"),
        )?;
        let s = &self.site_args;
        let mut site: Vec<String> = vec!["--scenario".into(), s.scenario.name.clone()];
        if let Some(r) = s.robots {
            site.extend(["--robots".into(), r.to_string()]);
        }
        if let Some(seed) = s.seed {
            site.extend(["--seed".into(), seed.to_string()]);
        }
        let speed = self.speed.to_string();
        let mut hardware_cmd = Command::new(&me);
        hardware_cmd
            .arg("hardware")
            .args(&site)
            .args(["--speed", &speed, "--connect", &endpoint]);
        if let Some(h) = s.humans {
            hardware_cmd.args(["--humans", &h.to_string()]);
        }
        let mut hardware =
            Process::spawn("hardware", &mut hardware_cmd, &logs.join("hardware.log"))?;
        let mut agents = Vec::with_capacity(robots);
        for i in 0..robots {
            let mut cmd = agent_command(
                &agent_exe,
                i,
                &self.planner.to_string(),
                &endpoint,
                scenario.humans.radius_m,
            );
            agents.push(Process::spawn(
                format!("agent {i}"),
                &mut cmd,
                &logs.join(format!("agent{i}.log")),
            )?);
        }
        let mut coordinator_cmd = Command::new(&me);
        coordinator_cmd
            .arg("coordinator")
            .args(&site)
            .args(["--humans", "0", "--live", "all", "--connect", &endpoint])
            .args(["--speed", &speed, "--seconds", &self.seconds.to_string()])
            .args(["--free-flow-planner", &self.planner.to_string()]);
        if let Some(dir) = &self.state {
            coordinator_cmd.arg("--state").arg(dir);
        }
        if let Some(rrd) = &self.rrd {
            coordinator_cmd.arg("--rrd").arg(rrd);
        }
        let coordinator_log = logs.join("coordinator.log");
        let mut coordinator =
            Process::spawn("coordinator", &mut coordinator_cmd, &coordinator_log)?;
        // SIGINT or SIGTERM ends the run early, as the coordinator's time would: the
        // coordinator first (it closes its journal), then the rest. Nothing is left running.
        let asked_to_stop = Arc::new(AtomicBool::new(false));
        let flag = asked_to_stop.clone();
        let signals = super::runtime()?;
        signals.spawn(async move {
            fleet_net::shutdown_signal().await;
            flag.store(true, Ordering::Relaxed);
        });
        let mut interrupted = false;
        let status = loop {
            if let Some(status) = coordinator.child.try_wait()? {
                break status;
            }
            if asked_to_stop.load(Ordering::Relaxed) && !interrupted {
                eprintln!("stopping: the coordinator first, then the agents and the hardware");
                coordinator.interrupt();
                interrupted = true;
            }
            std::thread::sleep(Duration::from_millis(100));
        };
        // The agents stop their robots when the coordinator's token goes; then the hardware.
        for agent in &mut agents {
            agent.interrupt();
        }
        for agent in &mut agents {
            agent.stop();
        }
        hardware.stop();
        println!("coordinator:\n{}", last_lines(&coordinator_log, "t "));
        println!(
            "hardware:\n{}",
            last_lines(&logs.join("hardware.log"), "t ")
        );
        if !status.success() {
            bail!(
                "the coordinator failed ({status}): see {}",
                coordinator_log.display()
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each agent drives its own robot's namespace and takes people at the site's size.
    #[test]
    fn agents_drive_their_robot_and_take_the_site_s_people() {
        let people = world_sim::scenario::Scenario::builtin("warehouse")
            .expect("the default warehouse")
            .humans
            .radius_m;
        let cmd = agent_command(
            Path::new("gapfleet-agent"),
            3,
            "pgp+orca",
            "tcp/x:1",
            people,
        );
        let args: Vec<String> = cmd
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let after = |flag: &str| {
            let at = args.iter().position(|a| a == flag).expect(flag);
            args[at + 1].clone()
        };
        assert_eq!(after("--robot-id"), "3");
        assert_eq!(after("--namespace"), "/robot3");
        assert_eq!(after("--person-radius").parse::<f64>(), Ok(0.35));
        assert_eq!(after("--planner"), "pgp+orca");
        assert!(args.contains(&"--ros".to_owned()));
    }
}
