//! The simulator's robots as ROS 2 robots over rmw_zenoh (`--ros`), so that agents in ROS mode
//! can be driven end to end without hardware. Robot `i` is the node `gapfleet_sim` in namespace
//! `/robot<i>`: every tick, just before its observation, it publishes `odom`
//! (`nav_msgs/Odometry`, in the map frame: the simulator's world frame), `scan` (a 360-ray
//! `sensor_msgs/LaserScan` of walls, shelves and the bodies in line of sight) and `people`
//! (`people_msgs/People`, the people its perception reports); it takes `cmd_vel`
//! (`geometry_msgs/Twist`, base frame).
//!
//! The robot then drives on its `cmd_vel`: the agent's fleet command still arrives (it answers
//! the observation, so freshness, round trips and the journal work as before), but its motion
//! is replaced by the newest `cmd_vel` ([`RosRobots::command`]).

use agent::map::{LocalMap, StaticMap};
use agent::math::{Real, Vec2};
use agent::model::Command;
use agent::visibility::Visibility;
use ros2_wire::graph::{self, Attachment, EntityKind, Node, Qos, gid_of};
use ros2_wire::msg::{
    Covariance, Header, LaserScan, Odometry, People, Person, Point, Pose, PoseWithCovariance,
    Quaternion, Time, Twist, TwistWithCovariance, Vector3,
};
use ros2_wire::{Distro, decode, encode};
use schemas::{Kind, Observation};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// How the simulated robots appear on ROS 2.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RosSimConfig {
    /// `ROS_DOMAIN_ID`.
    pub domain_id: u32,
    /// The type hashes in keys.
    pub distro: Distro,
}

impl Default for RosSimConfig {
    fn default() -> Self {
        Self {
            domain_id: 0,
            distro: Distro::Jazzy,
        }
    }
}

/// The namespace of simulated robot `i`.
pub fn namespace(i: usize) -> String {
    format!("/robot{i}")
}

/// The simulated scanner's reach (m) and rays per turn.
pub const SCAN_RANGE_M: Real = 12.0;
/// Rays per turn of the simulated scanner.
pub const SCAN_RAYS: usize = 360;
/// A simulated base stops when its newest `cmd_vel` is older than this (wall time), as a real
/// base's command watchdog does.
pub const CMD_VEL_TIMEOUT: std::time::Duration = std::time::Duration::from_millis(500);

struct Publisher {
    publisher: zenoh::pubsub::Publisher<'static>,
    gid: [u8; 16],
    seq: i64,
}

impl Publisher {
    async fn put(&mut self, bytes: Vec<u8>, stamp_ns: i64) {
        self.seq += 1;
        let attachment = Attachment {
            sequence: self.seq,
            timestamp_ns: stamp_ns,
            gid: self.gid,
        };
        if let Err(e) = self
            .publisher
            .put(bytes)
            .attachment(attachment.to_bytes().to_vec())
            .await
        {
            tracing::warn!("ROS 2 sample not sent: {e}");
        }
    }
}

struct Robot {
    odom: Publisher,
    scan: Publisher,
    people: Publisher,
    /// The newest `cmd_vel` and when it came.
    cmd: Arc<Mutex<Option<(Twist, std::time::Instant)>>>,
    /// `cmd_vel` messages accepted so far.
    cmd_count: Arc<AtomicU64>,
    _subscriber: zenoh::pubsub::Subscriber<()>,
    _tokens: Vec<zenoh::liveliness::LivelinessToken>,
}

impl std::fmt::Debug for Robot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Robot").finish_non_exhaustive()
    }
}

/// Every simulated robot's ROS 2 side.
#[derive(Debug)]
pub struct RosRobots {
    /// By robot id; `None` for a robot this process does not play.
    robots: Vec<Option<Robot>>,
    map: StaticMap,
    local: LocalMap,
    /// `cmd_vel` payloads refused.
    pub rejected: Arc<AtomicU64>,
    /// Added to the simulated time in every stamp (s): 0 when the robots share the
    /// coordinator's clock; a hardware process stamps with a clock of its own, as robots do.
    pub clock_offset_s: f64,
}

type ZResult<T> = Result<T, (String, zenoh::Error)>;

impl RosRobots {
    /// Declares `n` robots' nodes, publishers, subscriptions and tokens on `session`; `map` is
    /// what their scanners see besides bodies.
    pub async fn declare(
        session: &zenoh::Session,
        n: usize,
        map: StaticMap,
        config: &RosSimConfig,
    ) -> ZResult<Self> {
        Self::declare_some(session, &vec![true; n], map, config).await
    }

    /// Declares the robots whose entry in `played` is true (by robot id).
    pub async fn declare_some(
        session: &zenoh::Session,
        played: &[bool],
        map: StaticMap,
        config: &RosSimConfig,
    ) -> ZResult<Self> {
        let rejected = Arc::new(AtomicU64::new(0));
        let mut robots = Vec::with_capacity(played.len());
        for (i, &plays) in played.iter().enumerate() {
            robots.push(if plays {
                Some(declare_robot(session, i, config, rejected.clone()).await?)
            } else {
                None
            });
        }
        Ok(Self {
            robots,
            map,
            local: LocalMap::default(),
            rejected,
            clock_offset_s: 0.0,
        })
    }

    /// Publishes robot `obs.robot_id`'s odometry, scan and people for `obs`.
    pub async fn publish(&mut self, obs: &Observation) {
        let Some(Some(robot)) = self.robots.get_mut(obs.robot_id as usize) else {
            return;
        };
        let t = obs.sim_time + self.clock_offset_s;
        let stamp = Time::from_secs(t);
        let stamp_ns = (t * 1e9) as i64;
        let header = |frame: &str| Header {
            stamp: stamp.clone(),
            frame_id: frame.to_owned(),
        };
        // The simulator's heading is not wrapped; a scan's angles are kept within a turn.
        let heading = agent::math::wrap_angle(obs.heading);
        let (s, c) = heading.sin_cos();
        let odom = Odometry {
            header: header("map"),
            child_frame_id: format!("robot{}/base_link", obs.robot_id),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: Point {
                        x: obs.p.0,
                        y: obs.p.1,
                        z: 0.0,
                    },
                    orientation: Quaternion::from_yaw(heading),
                },
                covariance: Covariance::default(),
            },
            twist: TwistWithCovariance {
                twist: Twist {
                    // The base frame: the world velocity turned by −heading.
                    linear: Vector3 {
                        x: c * obs.vel.0 + s * obs.vel.1,
                        y: -s * obs.vel.0 + c * obs.vel.1,
                        z: 0.0,
                    },
                    angular: Vector3 {
                        x: 0.0,
                        y: 0.0,
                        z: obs.yaw_rate,
                    },
                },
                covariance: Covariance::default(),
            },
        };
        robot.odom.put(encode(&odom), stamp_ns).await;
        let origin = Vec2::new(obs.p.0, obs.p.1);
        let bodies: Vec<(Vec2, Real)> = obs
            .neighbours
            .iter()
            .map(|n| (Vec2::new(n.p.0, n.p.1), n.radius))
            .collect();
        let view = Visibility::scan(
            origin,
            SCAN_RANGE_M,
            SCAN_RAYS,
            &self.map,
            bodies,
            &mut self.local,
        );
        let step = view.step();
        let scan = LaserScan {
            // The simulated scanner sits at the base's centre: its frame is the base's.
            header: header(&format!("robot{}/base_link", obs.robot_id)),
            // The profile's ray 0 points along world +x; the scanner's along the heading.
            angle_min: (-heading) as f32,
            angle_max: (-heading + step * (SCAN_RAYS - 1) as Real) as f32,
            angle_increment: step as f32,
            time_increment: 0.0,
            scan_time: obs.dt as f32,
            range_min: 0.0,
            range_max: SCAN_RANGE_M as f32,
            ranges: view
                .ranges
                .iter()
                .map(|&r| {
                    if r >= SCAN_RANGE_M - 1e-9 {
                        f32::INFINITY
                    } else {
                        r as f32
                    }
                })
                .collect(),
            intensities: Vec::new(),
        };
        robot.scan.put(encode(&scan), stamp_ns).await;
        let people = People {
            header: header("map"),
            people: obs
                .neighbours
                .iter()
                .filter(|n| n.kind == Kind::Human)
                .map(|n| Person {
                    name: format!("person_{}", n.id),
                    position: Point {
                        x: n.p.0,
                        y: n.p.1,
                        z: 0.0,
                    },
                    velocity: Point {
                        x: n.vel.0,
                        y: n.vel.1,
                        z: 0.0,
                    },
                    reliability: 1.0,
                    tagnames: Vec::new(),
                    tags: Vec::new(),
                })
                .collect(),
        };
        robot.people.put(encode(&people), stamp_ns).await;
    }

    /// Robot `i`'s newest `cmd_vel` as a simulator command for a robot heading `heading`: a
    /// twist without turn as a world velocity (the simulator's robots are holonomic), one with
    /// a turn as forward speed and turn rate. `None` before the first `cmd_vel`, and once the
    /// newest is older than [`CMD_VEL_TIMEOUT`] (a base's watchdog stops it then).
    pub fn command(&self, i: usize, heading: Real) -> Option<Command> {
        let (twist, at) = self
            .robots
            .get(i)?
            .as_ref()?
            .cmd
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()?;
        (at.elapsed() <= CMD_VEL_TIMEOUT).then(|| command_of(&twist, heading))
    }

    /// How many `cmd_vel` messages robot `i` has accepted so far (0 for a robot this process
    /// does not play): between two ticks, none means the tick drives on the command the tick
    /// before drove on, and more than one means all but the newest never drove.
    pub fn commands_received(&self, i: usize) -> u64 {
        self.robots
            .get(i)
            .and_then(Option::as_ref)
            .map_or(0, |r| r.cmd_count.load(Ordering::Relaxed))
    }
}

/// A base-frame twist as a simulator command.
pub fn command_of(twist: &Twist, heading: Real) -> Command {
    if twist.angular.z == 0.0 {
        let (s, c) = heading.sin_cos();
        let (x, y) = (twist.linear.x, twist.linear.y);
        Command::Velocity(Vec2::new(c * x - s * y, s * x + c * y))
    } else {
        Command::Unicycle {
            speed: twist.linear.x,
            yaw_rate: twist.angular.z,
        }
    }
}

async fn declare_robot(
    session: &zenoh::Session,
    i: usize,
    config: &RosSimConfig,
    rejected: Arc<AtomicU64>,
) -> ZResult<Robot> {
    let ns = namespace(i);
    let node = Node {
        domain_id: config.domain_id,
        session_id: session.zid().to_string(),
        node_id: i as u32,
        namespace: ns.clone(),
        name: "gapfleet_sim".into(),
    };
    let d = config.distro;
    let err = |what: String| move |e: zenoh::Error| (what, e);
    let mut tokens = vec![
        session
            .liveliness()
            .declare_token(node.token())
            .await
            .map_err(err(format!("{ns} node")))?,
    ];
    macro_rules! publisher {
        ($ty:ty, $topic:expr, $entity:expr, $qos:expr) => {{
            let fq = format!("{ns}/{}", $topic);
            let token = node.endpoint_token::<$ty>($entity, EntityKind::Publisher, &fq, d, $qos);
            let gid = gid_of(&token);
            tokens.push(
                session
                    .liveliness()
                    .declare_token(token)
                    .await
                    .map_err(err(format!("{fq} token")))?,
            );
            let publisher = session
                .declare_publisher(graph::topic_key::<$ty>(config.domain_id, &fq, d))
                .await
                .map_err(err(format!("{fq} publisher")))?;
            Publisher {
                publisher,
                gid,
                seq: 0,
            }
        }};
    }
    let odom = publisher!(Odometry, "odom", 1, Qos::SENSOR_DATA);
    let scan = publisher!(LaserScan, "scan", 2, Qos::SENSOR_DATA);
    let people = publisher!(People, "people", 3, Qos::DEFAULT_10);
    let cmd_fq = format!("{ns}/cmd_vel");
    tokens.push(
        session
            .liveliness()
            .declare_token(node.endpoint_token::<Twist>(
                4,
                EntityKind::Subscription,
                &cmd_fq,
                d,
                Qos::DEFAULT_10,
            ))
            .await
            .map_err(err(format!("{cmd_fq} token")))?,
    );
    let cmd = Arc::new(Mutex::new(None));
    let slot = cmd.clone();
    let cmd_count = Arc::new(AtomicU64::new(0));
    let counted = cmd_count.clone();
    let subscriber = session
        .declare_subscriber(graph::topic_key::<Twist>(config.domain_id, &cmd_fq, d))
        .callback(
            move |sample| match decode::<Twist>(&sample.payload().to_bytes()) {
                Ok(twist) => {
                    let now = std::time::Instant::now();
                    *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some((twist, now));
                    counted.fetch_add(1, Ordering::Relaxed);
                }
                Err(e) => {
                    let n = rejected.fetch_add(1, Ordering::Relaxed) + 1;
                    if n.is_power_of_two() {
                        tracing::warn!(robot = i, rejected = n, "bad cmd_vel refused: {e}");
                    }
                }
            },
        )
        .await
        .map_err(err(format!("{cmd_fq} subscriber")))?;
    Ok(Robot {
        odom,
        scan,
        people,
        cmd,
        cmd_count,
        _subscriber: subscriber,
        _tokens: tokens,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twists_become_simulator_commands() {
        let forward = Twist {
            linear: Vector3 {
                x: 1.0,
                y: 0.0,
                z: 0.0,
            },
            ..Default::default()
        };
        let Command::Velocity(v) = command_of(&forward, std::f64::consts::FRAC_PI_2) else {
            panic!("a velocity")
        };
        assert!(v.x.abs() < 1e-12 && (v.y - 1.0).abs() < 1e-12);
        let turning = Twist {
            linear: Vector3 {
                x: 0.5,
                y: 0.0,
                z: 0.0,
            },
            angular: Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.3,
            },
        };
        assert_eq!(
            command_of(&turning, 1.0),
            Command::Unicycle {
                speed: 0.5,
                yaw_rate: 0.3
            }
        );
    }
}
