//! `gapfleet study traffic`: fleets of several sizes, the traffic policy off and on.

use crate::cli::positive;
use agent::planner::PlannerSpec;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use studies::traffic::{self as traffic_study, TrafficStudy};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

/// `study traffic`'s arguments.
#[derive(Debug, clap::Args)]
pub struct TrafficArgs {
    /// Seeds per (site, fleet size, policy).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    seeds: u64,
    #[command(flatten)]
    first: super::FirstSeed,
    /// Simulated seconds per run.
    #[arg(long, default_value_t = 300.0, value_parser = positive)]
    seconds: f64,
    /// Fleet sizes in the narrow-aisle warehouse (`warehouse-narrow`), comma-separated; empty
    /// (`''`) or `0` for none.
    #[arg(long, default_value = "10,20,40", value_parser = fleet_sizes)]
    narrow_fleets: FleetSizes,
    /// Fleet sizes in the fleet hallway (`hallway-fleet`), comma-separated; empty or `0` for none.
    #[arg(long, default_value = "10,20", value_parser = fleet_sizes)]
    hallway_fleets: FleetSizes,
    /// Fleet sizes in the default warehouse (`warehouse`), comma-separated; empty (the
    /// default) or `0` for none.
    #[arg(long, default_value = "", value_parser = fleet_sizes)]
    warehouse_fleets: FleetSizes,
    /// Another site with its fleet sizes, as `SCENARIO=4,8,16`: a built-in scenario (e.g.
    /// `aws-small-warehouse`, the real floor plan) or a scenario file. Repeat for several.
    #[arg(long = "site", value_parser = site_fleets)]
    sites: Vec<SiteFleets>,
    /// The traffic policy off, on, or both (`off,on`), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "off,on", value_parser = on_off)]
    policy: Vec<bool>,
    /// The safety layer off, on, or both (`off,on`), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "on", value_parser = on_off)]
    safety: Vec<bool>,
    /// Changes to every site's safety-layer parameters (`[robot.safety_layer]`), as
    /// `key=value,…`: e.g. `yield_time=3,yield_clearance=0.6`.
    #[arg(long, default_value = "")]
    safety_layer: String,
    /// Changes to the traffic policy's parameters (`world_sim::traffic_policy::PolicyParams`),
    /// as `key=value,…`: e.g. `people_route_weight_m=5`.
    #[arg(long, default_value = "")]
    policy_params: String,
    /// Take runs from this earlier `runs.csv` instead of running them again, for the policy
    /// settings given here (`off`, `on`): only for settings whose code has not changed.
    #[arg(long, requires = "reuse_policy")]
    reuse: Option<PathBuf>,
    /// The policy settings to take from `--reuse`, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = on_off, requires = "reuse")]
    reuse_policy: Vec<bool>,
    /// Planner stack of every robot.
    #[arg(long, default_value = agent::planner::PlannerSpec::FLEET)]
    planner: PlannerSpec,
    #[command(flatten)]
    run: super::RunArgs,
    /// Output folder.
    #[arg(long, default_value = "results/traffic")]
    out: PathBuf,
}

/// Fleet sizes, comma-separated; the empty list (`''`, or `0` alone) leaves a site out.
#[derive(Debug, Clone)]
struct FleetSizes(Vec<usize>);

fn fleet_sizes(s: &str) -> Result<FleetSizes, String> {
    if s.trim().is_empty() || s.trim() == "0" {
        return Ok(FleetSizes(Vec::new()));
    }
    s.split(',')
        .map(|n| match n.trim().parse() {
            Ok(0) => Err(
                "fleet size 0 in a list: give `0` or `''` alone to leave the site out".to_owned(),
            ),
            Ok(size) => Ok(size),
            Err(e) => Err(format!("fleet size `{n}`: {e}")),
        })
        .collect::<Result<_, _>>()
        .map(FleetSizes)
}

/// A scenario and its fleet sizes (`--site`).
#[derive(Debug, Clone)]
struct SiteFleets {
    scenario: crate::cli::ScenarioRef,
    fleets: Vec<usize>,
}

fn site_fleets(s: &str) -> Result<SiteFleets, String> {
    let (name, sizes) = s
        .rsplit_once('=')
        .ok_or_else(|| format!("`{s}` is not SCENARIO=SIZES (e.g. aws-small-warehouse=4,8,16)"))?;
    let fleets = fleet_sizes(sizes)?.0;
    if fleets.is_empty() {
        return Err(format!("`{s}` gives no fleet sizes"));
    }
    let scenario = name.parse().map_err(|e: anyhow::Error| format!("{e:#}"))?;
    Ok(SiteFleets { scenario, fleets })
}

/// `on` or `off`.
fn on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{s}` is neither `on` nor `off`")),
    }
}

/// Runs the study and writes its outputs.
pub(super) fn run(args: TrafficArgs) -> Result<()> {
    let mut sites = Vec::new();
    let named = [
        ("warehouse", args.warehouse_fleets.0),
        ("warehouse-narrow", args.narrow_fleets.0),
        ("hallway-fleet", args.hallway_fleets.0),
    ]
    .into_iter()
    .map(|(name, fleets)| {
        Ok::<_, anyhow::Error>((name.to_owned(), Scenario::builtin(name)?, fleets))
    });
    let more = args
        .sites
        .into_iter()
        .map(|s| Ok((s.scenario.name, *s.scenario.scenario, s.fleets)));
    for site in named.chain(more) {
        let (name, mut scenario, fleets): (String, Scenario, Vec<usize>) = site?;
        if fleets.is_empty() {
            continue;
        }
        if scenario.fleet_size().is_none() {
            bail!(
                "{name} is not a fleet site (it needs a [warehouse] or [floor_plan] table, or a [hallway] with robots = N)"
            );
        }
        let most = world_sim::scenario::MAX_ROBOTS;
        if let Some(&bad) = fleets.iter().find(|&&n| !(1..=most).contains(&n)) {
            bail!("fleet size {bad} for {name} is not in [1, {most}]");
        }
        scenario.robot.safety_layer = scenario
            .robot
            .safety_layer
            .with_overrides(&args.safety_layer)
            .map_err(|e| anyhow::anyhow!("--safety-layer: {e}"))?;
        sites.push(traffic_study::Site { scenario, fleets });
    }
    if sites.is_empty() {
        bail!(
            "no fleet sizes given: --warehouse-fleets, --narrow-fleets, --hallway-fleets and --site are all empty"
        );
    }
    if args.first.first_seed.checked_add(args.seeds).is_none() {
        bail!(
            "--first-seed {} with --seeds {} runs past the last seed",
            args.first.first_seed,
            args.seeds
        );
    }
    let mut policies = args.policy;
    policies.sort_unstable();
    policies.dedup();
    let mut layers = args.safety;
    layers.sort_unstable();
    layers.dedup();
    let policy_params = PolicyParams::default()
        .with_overrides(&args.policy_params)
        .map_err(|e| anyhow::anyhow!("--policy-params: {e}"))?;
    let study = TrafficStudy {
        sites,
        planner: args.planner,
        first_seed: args.first.first_seed,
        seeds: args.seeds,
        policies,
        layers,
        seconds: args.seconds,
        policy_params,
    };
    let earlier = match &args.reuse {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            let mut runs = traffic_study::parse_runs(&text).with_context(|| {
                format!("reading {} as a traffic study's runs.csv", path.display())
            })?;
            runs.retain(|r| args.reuse_policy.contains(&r.policy));
            eprintln!("reusing {} runs from {}", runs.len(), path.display());
            runs
        }
        None => Vec::new(),
    };
    let (runner, done) = args.run.run(
        &args.out,
        &traffic_study::Reusing {
            study: &study,
            earlier: &earlier,
        },
    )?;
    let runs = done.rows;
    let cells = traffic_study::write_outputs(&args.out, &study, &runs)?;
    runner.finish()?;
    eprintln!(
        "wrote {}/runs.csv, summary.json, summary.md and throughput.png",
        args.out.display(),
    );
    print!("{}", traffic_study::table(&cells));
    println!("\nContacts of every cause, closeness and the safety layer:");
    print!("{}", traffic_study::contacts_table(&cells));
    println!("\nWhere the stuck robot-seconds went:");
    print!("{}", traffic_study::stuck_table(&cells));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: `--narrow-fleets 0` failed when the study started, after the other flags
    /// were read, instead of leaving the site out as `''` does.
    #[test]
    fn a_lone_zero_leaves_a_site_out_and_a_zero_in_a_list_is_refused() {
        assert!(fleet_sizes("0").expect("`0` alone").0.is_empty());
        assert!(fleet_sizes(" ").expect("empty").0.is_empty());
        assert_eq!(fleet_sizes("10, 20").expect("a list").0, vec![10, 20]);
        let error = fleet_sizes("0,20").expect_err("0 in a list");
        assert!(error.contains("fleet size 0"), "{error}");
        assert!(fleet_sizes("ten").is_err());
        assert!(
            site_fleets("warehouse=0").is_err(),
            "a --site with no fleet"
        );
    }
}
