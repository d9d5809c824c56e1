//! The robot an agent drives, when it is a ROS 2 robot on rmw_zenoh: the agent joins the
//! robot's Zenoh network as a ROS 2 node (`gapfleet_agent` in the robot's namespace, with
//! rmw_zenoh's liveliness tokens, so `ros2 node list` and `ros2 topic info` show it), reads
//! `nav_msgs/Odometry`, `sensor_msgs/LaserScan`, `people_msgs/People` and, when the map frame is
//! not the odometry frame, `/tf`, and publishes `geometry_msgs/Twist` (or `TwistStamped`) on
//! `cmd_vel`. Keys, tokens, CDR and attachments come from `ros2_wire`.
//!
//! Every payload is decoded strictly (`ros2_wire::decode`); a bad one is counted and logged,
//! rate-limited, and never stops the agent. [`RosLink::sensed`] turns the newest of each into
//! what the planners take: the robot's state in the map frame, the tracked people, the scan.

use crate::math::{Real, Vec2};
use crate::model::{AgentKind, Command, EgoState, Neighbour};
use crate::scan::Scan;
use ros2_wire::graph::{self, Attachment, EntityKind, Node, Qos, gid_of};
use ros2_wire::msg::{
    Header, LaserScan, Odometry, People, TFMessage, Time, Twist, TwistStamped, Vector3,
};
use ros2_wire::{Distro, Message, decode, encode};
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// How the agent finds the robot on ROS 2.
#[derive(Debug, Clone, PartialEq)]
pub struct RosConfig {
    /// `ROS_DOMAIN_ID`.
    pub domain_id: u32,
    /// The robot's namespace (`/robot1`; `/` for none). Relative topics resolve in it.
    pub namespace: String,
    /// The distribution the robot runs (type hashes in keys).
    pub distro: Distro,
    /// Publish `TwistStamped` (Jazzy's Nav2 default) instead of `Twist`.
    pub stamped_cmd: bool,
    /// The map frame's name. When odometry's frame is another, the agent needs map→odom on
    /// `/tf`; when it is this frame, odometry is already in the map frame.
    pub map_frame: String,
    /// Topics (relative ones in the namespace).
    pub odom_topic: String,
    /// Laser scan topic.
    pub scan_topic: String,
    /// Tracked people topic.
    pub people_topic: String,
    /// Command topic.
    pub cmd_topic: String,
    /// Transform topic.
    pub tf_topic: String,
    /// The robot's body radius (m).
    pub robot_radius: Real,
    /// A person's body radius for the planners (m): `people_msgs` carries none.
    pub person_radius: Real,
    /// Odometry older than this is not the robot's state any more (the agent stops).
    pub odom_timeout: Duration,
}

impl Default for RosConfig {
    fn default() -> Self {
        Self {
            domain_id: 0,
            namespace: "/".into(),
            distro: Distro::Jazzy,
            stamped_cmd: false,
            map_frame: "map".into(),
            odom_topic: "odom".into(),
            scan_topic: "scan".into(),
            people_topic: "people".into(),
            cmd_topic: "cmd_vel".into(),
            tf_topic: "/tf".into(),
            robot_radius: 0.3,
            person_radius: 0.3,
            odom_timeout: Duration::from_millis(500),
        }
    }
}

/// Odometry stamped within this of an observation's time is on the same clock (s).
pub const SHARED_CLOCK_S: Real = 1.0;

/// Odometry poses kept to place scans at their own time (2 s at 10 Hz).
const POSE_HISTORY: usize = 20;
/// A scan is placed at an odometry pose at most this far from its stamp (s).
pub const SCAN_POSE_TOLERANCE_S: Real = 0.06;

/// Counts of what arrived from the robot.
#[derive(Debug, Default)]
pub struct RosCounters {
    /// Odometry messages accepted.
    pub odom: AtomicU64,
    /// Scans accepted.
    pub scans: AtomicU64,
    /// People messages accepted.
    pub people: AtomicU64,
    /// Transform messages accepted.
    pub tf: AtomicU64,
    /// Payloads refused (bad CDR, out of bounds, unknown frame).
    pub rejected: AtomicU64,
    /// Commands published.
    pub commands: AtomicU64,
}

/// What the robot reported most recently.
#[derive(Debug, Default)]
struct Latest {
    odom: Option<(Odometry, Instant)>,
    /// Recent odometry poses (stamp in s, position, yaw in the odometry frame), oldest first:
    /// a scan is placed at the pose of its own stamp, since its samples need not arrive in
    /// step with odometry's.
    poses: std::collections::VecDeque<(Real, Vec2, Real)>,
    /// map → odom (x, y, yaw), from `/tf`.
    map_from_odom: Option<(Vec2, Real)>,
    people: Option<People>,
    scan: Option<LaserScan>,
}

/// The robot as the planners see it, in the map frame.
#[derive(Debug, Clone)]
pub struct Sensed {
    /// The robot.
    pub ego: EgoState,
    /// Tracked people.
    pub people: Vec<Neighbour>,
    /// The newest scan, placed at the robot's pose.
    pub scan: Option<Scan>,
    /// How long ago the odometry behind `ego` arrived.
    pub odom_age: Duration,
}

/// Why the link could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum RosError {
    /// A bad namespace, topic or node name.
    #[error(transparent)]
    Name(#[from] graph::NameError),
    /// Zenoh refused a declaration.
    #[error("{what}: {source}")]
    Zenoh {
        /// What was being declared.
        what: String,
        /// Zenoh's error.
        source: zenoh::Error,
    },
}

/// An agent's ROS 2 side: its node, subscriptions and command publisher, live while held.
#[derive(Debug)]
pub struct RosLink {
    config: RosConfig,
    latest: Arc<Mutex<Latest>>,
    /// Signalled on every accepted odometry, scan and people message.
    odom_arrived: Arc<tokio::sync::Notify>,
    counters: Arc<RosCounters>,
    cmd_pub: zenoh::pubsub::Publisher<'static>,
    cmd_gid: [u8; 16],
    cmd_seq: AtomicI64,
    _tokens: Vec<zenoh::liveliness::LivelinessToken>,
    _subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
}

/// Logs the 1st, 10th, 100th, … rejection of a kind.
fn log_now(n: u64) -> bool {
    n > 0 && 10u64.pow(n.ilog10()) == n
}

impl RosLink {
    /// Declares the node, its subscriptions and its command publisher on `session`.
    pub async fn declare(
        session: &zenoh::Session,
        config: RosConfig,
        counters: Arc<RosCounters>,
    ) -> Result<Self, RosError> {
        let namespace = graph::namespace(&config.namespace)?;
        let node = Node {
            domain_id: config.domain_id,
            session_id: session.zid().to_string(),
            node_id: 0,
            namespace: namespace.clone(),
            name: graph::node_name("gapfleet_agent")?.to_owned(),
        };
        let zerr = |what: String| move |source: zenoh::Error| RosError::Zenoh { what, source };
        let mut tokens = vec![
            session
                .liveliness()
                .declare_token(node.token())
                .await
                .map_err(zerr("node token".into()))?,
        ];
        let latest = Arc::new(Mutex::new(Latest::default()));
        let mut subscribers = Vec::new();
        let mut entity = 0u32;
        let d = config.distro;
        macro_rules! sub {
            ($ty:ty, $topic:expr, $qos:expr, $accept:expr) => {{
                let fq = graph::fully_qualified(&namespace, $topic)?;
                let key = graph::topic_key::<$ty>(config.domain_id, &fq, d);
                entity += 1;
                let token = node.endpoint_token::<$ty>(entity, EntityKind::Subscription, &fq, d, $qos);
                let latest = latest.clone();
                let counters = counters.clone();
                let accept = $accept;
                let topic = fq.clone();
                let on = Box::new(move |bytes: &[u8]| match decode::<$ty>(bytes) {
                    Ok(m) => {
                        let mut l = latest.lock().unwrap_or_else(|e| e.into_inner());
                        accept(&mut l, m, &counters);
                    }
                    Err(e) => {
                        let n = counters.rejected.fetch_add(1, Ordering::Relaxed) + 1;
                        if log_now(n) {
                            tracing::warn!(topic = %topic, rejected = n, "bad {} refused: {e}", <$ty>::NAME);
                        }
                    }
                });
                tokens.push(
                    session
                        .liveliness()
                        .declare_token(token)
                        .await
                        .map_err(zerr(format!("token for {fq}")))?,
                );
                subscribers.push(
                    session
                        .declare_subscriber(key)
                        .callback(move |sample| on(&sample.payload().to_bytes()))
                        .await
                        .map_err(zerr(format!("subscriber on {fq}")))?,
                );
            }};
        }
        let map_frame = config.map_frame.clone();
        let odom_arrived = Arc::new(tokio::sync::Notify::new());
        let arrived = odom_arrived.clone();
        let scan_arrived = odom_arrived.clone();
        let people_arrived = odom_arrived.clone();
        sub!(
            Odometry,
            &config.odom_topic,
            Qos::SENSOR_DATA,
            move |l: &mut Latest, m: Odometry, c: &RosCounters| {
                c.odom.fetch_add(1, Ordering::Relaxed);
                let p = &m.pose.pose;
                if l.poses.len() == POSE_HISTORY {
                    l.poses.pop_front();
                }
                l.poses.push_back((
                    m.header.stamp.as_secs(),
                    Vec2::new(p.position.x, p.position.y),
                    p.orientation.yaw(),
                ));
                l.odom = Some((m, Instant::now()));
                arrived.notify_waiters();
            }
        );
        sub!(
            LaserScan,
            &config.scan_topic,
            Qos::SENSOR_DATA,
            move |l: &mut Latest, m: LaserScan, c: &RosCounters| {
                c.scans.fetch_add(1, Ordering::Relaxed);
                l.scan = Some(m);
                scan_arrived.notify_waiters();
            }
        );
        sub!(
            People,
            &config.people_topic,
            Qos::DEFAULT_10,
            move |l: &mut Latest, m: People, c: &RosCounters| {
                c.people.fetch_add(1, Ordering::Relaxed);
                l.people = Some(m);
                people_arrived.notify_waiters();
            }
        );
        sub!(
            TFMessage,
            &config.tf_topic,
            Qos::DEFAULT_10,
            move |l: &mut Latest, m: TFMessage, c: &RosCounters| {
                for t in &m.transforms {
                    if t.header.frame_id.trim_start_matches('/') == map_frame {
                        c.tf.fetch_add(1, Ordering::Relaxed);
                        let tr = &t.transform;
                        l.map_from_odom = Some((
                            Vec2::new(tr.translation.x, tr.translation.y),
                            tr.rotation.yaw(),
                        ));
                    }
                }
            }
        );
        let cmd_fq = graph::fully_qualified(&namespace, &config.cmd_topic)?;
        let (cmd_key, cmd_token) = if config.stamped_cmd {
            (
                graph::topic_key::<TwistStamped>(config.domain_id, &cmd_fq, d),
                node.endpoint_token::<TwistStamped>(
                    10,
                    EntityKind::Publisher,
                    &cmd_fq,
                    d,
                    Qos::DEFAULT_10,
                ),
            )
        } else {
            (
                graph::topic_key::<Twist>(config.domain_id, &cmd_fq, d),
                node.endpoint_token::<Twist>(
                    10,
                    EntityKind::Publisher,
                    &cmd_fq,
                    d,
                    Qos::DEFAULT_10,
                ),
            )
        };
        let cmd_gid = gid_of(&cmd_token);
        tokens.push(
            session
                .liveliness()
                .declare_token(cmd_token)
                .await
                .map_err(zerr("command publisher token".into()))?,
        );
        let cmd_pub = session
            .declare_publisher(cmd_key)
            .await
            .map_err(zerr("command publisher".into()))?;
        tracing::info!(namespace = %namespace, cmd = %cmd_fq, distro = %d, "ROS 2 node gapfleet_agent up");
        Ok(Self {
            config,
            latest,
            odom_arrived,
            counters,
            cmd_pub,
            cmd_gid,
            cmd_seq: AtomicI64::new(0),
            _tokens: tokens,
            _subscribers: subscribers,
        })
    }

    /// Waits up to `timeout` for odometry (and people and scan, if the robot sends them)
    /// stamped at `time` or later, when the robot's clock is
    /// the caller's (within [`SHARED_CLOCK_S`]: the simulator's robots stamp with simulated
    /// time, as its observations do), so that a plan uses the robot's state at the
    /// observation's instant rather than one period before it. A robot on a clock of its own
    /// returns at once.
    pub async fn wait_for_odometry(&self, time: Real, timeout: Duration) {
        let deadline = tokio::time::Instant::now() + timeout;
        loop {
            let arrived = self.odom_arrived.notified();
            let caught_up = {
                let l = self.latest.lock().unwrap_or_else(|e| e.into_inner());
                // Each stream the robot has (odometry always; people and scan once seen) is at
                // `time`, or on a clock of its own.
                let at =
                    |stamp: Real| stamp >= time - 1e-6 || (stamp - time).abs() > SHARED_CLOCK_S;
                l.odom
                    .as_ref()
                    .is_some_and(|(o, _)| at(o.header.stamp.as_secs()))
                    && l.people
                        .as_ref()
                        .is_none_or(|p| at(p.header.stamp.as_secs()))
                    && l.scan.as_ref().is_none_or(|s| at(s.header.stamp.as_secs()))
            };
            if caught_up {
                return;
            }
            if tokio::time::timeout_at(deadline, arrived).await.is_err() {
                return;
            }
        }
    }

    /// The robot's newest state in the map frame, its tracked people and its scan; `None`
    /// until fresh odometry (and, if the odometry frame is not the map frame, map→odom) came.
    pub fn sensed(&self) -> Option<Sensed> {
        let l = self.latest.lock().unwrap_or_else(|e| e.into_inner());
        let (_, at) = l.odom.as_ref()?;
        let odom_age = at.elapsed();
        if odom_age > self.config.odom_timeout {
            return None;
        }
        sense(&l, &self.config).map(|s| Sensed { odom_age, ..s })
    }

    /// Sends `command` (already executable on the base) to the robot's `cmd_vel`, in the base
    /// frame of a robot heading `heading` in the map frame.
    pub async fn drive(&self, command: Command, heading: Real) {
        let twist = twist_of(command, heading);
        let now = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .unwrap_or_default();
        let bytes = if self.config.stamped_cmd {
            encode(&TwistStamped {
                header: Header {
                    stamp: Time::from_secs(now.as_secs_f64()),
                    frame_id: "base_link".into(),
                },
                twist,
            })
        } else {
            encode(&twist)
        };
        let attachment = Attachment {
            sequence: self.cmd_seq.fetch_add(1, Ordering::Relaxed) + 1,
            timestamp_ns: i64::try_from(now.as_nanos()).unwrap_or(i64::MAX),
            gid: self.cmd_gid,
        };
        match self
            .cmd_pub
            .put(bytes)
            .attachment(attachment.to_bytes().to_vec())
            .await
        {
            Ok(()) => {
                self.counters.commands.fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => tracing::warn!("cmd_vel not sent: {e}"),
        }
    }
}

/// The newest of each stream as the planners' input in the map frame; `None` without odometry
/// or, when odometry is not in the map frame, without map→odom.
fn sense(l: &Latest, config: &RosConfig) -> Option<Sensed> {
    let (odom, _) = l.odom.as_ref()?;
    let odom_frame = odom.header.frame_id.trim_start_matches('/');
    let (offset, rotation) = if odom_frame == config.map_frame {
        (Vec2::zeros(), 0.0)
    } else {
        l.map_from_odom?
    };
    let to_map = |p: Vec2| offset + rotate(p, rotation);
    let pose = &odom.pose.pose;
    let heading = pose.orientation.yaw() + rotation;
    let body_v = &odom.twist.twist.linear;
    let ego = EgoState {
        position: to_map(Vec2::new(pose.position.x, pose.position.y)),
        heading,
        // Odometry's twist is in the child (base) frame.
        velocity: rotate(Vec2::new(body_v.x, body_v.y), heading),
        yaw_rate: odom.twist.twist.angular.z,
        radius: config.robot_radius,
    };
    let people = l
        .people
        .as_ref()
        .filter(|p| {
            let frame = p.header.frame_id.trim_start_matches('/');
            frame == config.map_frame || frame == odom_frame
        })
        .map(|p| {
            let in_odom = p.header.frame_id.trim_start_matches('/') != config.map_frame;
            p.people
                .iter()
                .enumerate()
                .map(|(i, person)| {
                    let pos = Vec2::new(person.position.x, person.position.y);
                    let vel = Vec2::new(person.velocity.x, person.velocity.y);
                    let (pos, vel) = if in_odom {
                        (to_map(pos), rotate(vel, rotation))
                    } else {
                        (pos, vel)
                    };
                    Neighbour::new(
                        person_id(&person.name, i),
                        pos,
                        vel,
                        config.person_radius,
                        AgentKind::Human,
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    // The scanner is taken to sit at the base's centre, facing forward, and the scan is
    // placed at the odometry pose nearest its stamp; a scan with no pose within
    // SCAN_POSE_TOLERANCE_S of its stamp is not used.
    let scan = l.scan.as_ref().and_then(|s| {
        let at = s.header.stamp.as_secs();
        let &(_, position, yaw) = l
            .poses
            .iter()
            .min_by(|a, b| (a.0 - at).abs().total_cmp(&(b.0 - at).abs()))
            .filter(|(t, ..)| (t - at).abs() <= SCAN_POSE_TOLERANCE_S)?;
        Some(Scan {
            origin: to_map(position),
            bearing0: yaw + rotation + Real::from(s.angle_min),
            increment: Real::from(s.angle_increment),
            range_min: Real::from(s.range_min),
            range_max: Real::from(s.range_max),
            ranges: s.ranges.clone(),
        })
    });
    Some(Sensed {
        ego,
        people,
        scan,
        odom_age: Duration::ZERO,
    })
}

/// A tracked person's id, stable while the tracker keeps the name: a 47-bit hash of it above
/// 2⁴⁷ (above any robot's id, below the scan bodies'); the index when the name is empty.
fn person_id(name: &str, index: usize) -> u64 {
    const HIGH: u64 = 1 << 47;
    if name.is_empty() {
        return HIGH + index as u64;
    }
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    HIGH | (hash & (HIGH - 1))
}

fn rotate(v: Vec2, angle: Real) -> Vec2 {
    let (s, c) = angle.sin_cos();
    Vec2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// A command as a base-frame twist for a robot heading `heading`: a velocity command's world
/// velocity turned into the base frame (an omnidirectional base's `linear.y`), a unicycle
/// command as forward speed and turn rate.
pub fn twist_of(command: Command, heading: Real) -> Twist {
    match command {
        Command::Velocity(v) => {
            let body = rotate(v, -heading);
            Twist {
                linear: Vector3 {
                    x: body.x,
                    y: body.y,
                    z: 0.0,
                },
                angular: Vector3::default(),
            }
        }
        Command::Unicycle { speed, yaw_rate } => Twist {
            linear: Vector3 {
                x: speed,
                y: 0.0,
                z: 0.0,
            },
            angular: Vector3 {
                x: 0.0,
                y: 0.0,
                z: yaw_rate,
            },
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_become_base_frame_twists() {
        let t = twist_of(
            Command::Velocity(Vec2::new(0.0, 1.0)),
            std::f64::consts::FRAC_PI_2,
        );
        assert!((t.linear.x - 1.0).abs() < 1e-12 && t.linear.y.abs() < 1e-12);
        let t = twist_of(
            Command::Unicycle {
                speed: 0.5,
                yaw_rate: -0.2,
            },
            1.0,
        );
        assert_eq!((t.linear.x, t.angular.z), (0.5, -0.2));
    }

    fn odometry(frame: &str, stamp: f64, x: Real, y: Real, yaw: Real, forward: Real) -> Odometry {
        let mut o = Odometry {
            header: Header {
                stamp: Time::from_secs(stamp),
                frame_id: frame.into(),
            },
            ..Default::default()
        };
        o.pose.pose.position = ros2_wire::msg::Point { x, y, z: 0.0 };
        o.pose.pose.orientation = ros2_wire::msg::Quaternion::from_yaw(yaw);
        o.twist.twist.linear.x = forward;
        o
    }

    fn near(a: Vec2, b: Vec2) -> bool {
        (a - b).norm() < 1e-9
    }

    /// Odometry in `odom`, map→odom from /tf (1 m along x, a quarter turn), people in the odom
    /// frame, and a scan older than the newest odometry: all land in the map frame, the scan
    /// at the pose of its own stamp.
    #[test]
    fn frames_compose_into_the_map_frame() {
        use std::f64::consts::FRAC_PI_2;
        let config = RosConfig::default();
        let mut l = Latest {
            odom: Some((odometry("odom", 2.0, 2.0, 0.0, 0.0, 0.5), Instant::now())),
            ..Default::default()
        };
        l.poses.push_back((1.9, Vec2::new(1.95, 0.0), 0.0));
        l.poses.push_back((2.0, Vec2::new(2.0, 0.0), 0.0));
        assert!(sense(&l, &config).is_none(), "no map→odom yet");
        l.map_from_odom = Some((Vec2::new(1.0, 0.0), FRAC_PI_2));
        l.people = Some(People {
            header: Header {
                stamp: Time::from_secs(2.0),
                frame_id: "odom".into(),
            },
            people: vec![ros2_wire::msg::Person {
                name: "a".into(),
                position: ros2_wire::msg::Point {
                    x: 3.0,
                    y: 0.0,
                    z: 0.0,
                },
                velocity: ros2_wire::msg::Point {
                    x: 1.0,
                    y: 0.0,
                    z: 0.0,
                },
                ..Default::default()
            }],
        });
        l.scan = Some(LaserScan {
            header: Header {
                stamp: Time::from_secs(1.9),
                frame_id: "base_scan".into(),
            },
            angle_min: 0.5,
            angle_increment: 0.01,
            range_max: 10.0,
            ranges: vec![1.0],
            ..Default::default()
        });
        let s = sense(&l, &config).expect("sensed");
        // (2, 0) in odom is (1, 2) in the map; heading a quarter turn; forward is map +y.
        assert!(
            near(s.ego.position, Vec2::new(1.0, 2.0)),
            "{:?}",
            s.ego.position
        );
        assert!((s.ego.heading - FRAC_PI_2).abs() < 1e-12);
        assert!(
            near(s.ego.velocity, Vec2::new(0.0, 0.5)),
            "{:?}",
            s.ego.velocity
        );
        assert!(near(s.people[0].position, Vec2::new(1.0, 3.0)));
        assert!(near(s.people[0].velocity, Vec2::new(0.0, 1.0)));
        let scan = s.scan.expect("the scan, at its own pose");
        assert!(near(scan.origin, Vec2::new(1.0, 1.95)), "{:?}", scan.origin);
        assert!((scan.bearing0 - (FRAC_PI_2 + 0.5)).abs() < 1e-6);
        // A scan with no odometry near its stamp is not used.
        if let Some(scan) = l.scan.as_mut() {
            scan.header.stamp = Time::from_secs(1.0);
        }
        assert!(sense(&l, &config).expect("sensed").scan.is_none());
        // People in another frame are refused.
        if let Some(p) = l.people.as_mut() {
            p.header.frame_id = "camera".into();
        }
        assert!(sense(&l, &config).expect("sensed").people.is_empty());
    }

    #[test]
    fn rejections_are_logged_at_powers_of_ten() {
        let logged: Vec<u64> = (0..2000).filter(|&n| log_now(n)).collect();
        assert_eq!(logged, vec![1, 10, 100, 1000]);
    }
}
