//! The robot an agent drives, when it is a ROS 2 robot on rmw_zenoh: the agent joins the
//! robot's Zenoh network as a ROS 2 node (`gapfleet_agent` in the robot's namespace, with
//! rmw_zenoh's liveliness tokens, so `ros2 node list` and `ros2 topic info` show it), reads
//! `nav_msgs/Odometry`, `sensor_msgs/LaserScan`, `people_msgs/People` and, when the map frame is
//! not the odometry frame, `/tf` (or a pose topic such as AMCL's), `/tf_static` for where the
//! scanner sits on the base, and publishes `geometry_msgs/Twist` (or `TwistStamped`) on
//! `cmd_vel`. Keys, tokens, CDR and attachments come from `ros2_wire`.
//!
//! Every payload is decoded strictly (`ros2_wire::decode`); a bad one is counted and logged,
//! rate-limited, and never stops the agent. [`RosLink::sensed`] turns the newest of each into
//! what the planners take: the robot's state in the map frame, the tracked people, the scan.

use crate::math::{Real, Vec2};
use crate::model::{AgentKind, Command, EgoState, Neighbour};
use crate::scan::Scan;
use frames::{ask_static_history, mount_of, pose_at, take_map_pose, take_transforms};
use ros2_wire::graph::{self, Attachment, EntityKind, Node, Qos, gid_of};
use ros2_wire::msg::{
    Header, LaserScan, Odometry, People, PoseWithCovarianceStamped, TFMessage, Time, Twist,
    TwistStamped, Vector3,
};
use ros2_wire::{Distro, Message, decode, encode};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

mod frames;

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
    /// Static transform topic (transient local): where the scanner sits on the base.
    pub tf_static_topic: String,
    /// A pose topic in the map frame (`geometry_msgs/PoseWithCovarianceStamped`, e.g. AMCL's
    /// `amcl_pose`). When set, map→odom comes from it rather than from `/tf`.
    pub pose_topic: Option<String>,
    /// The scanner's mounting on the base (offset in m, yaw in rad); when set, it overrides
    /// what `/tf` and `/tf_static` say.
    pub scan_mount: Option<(Vec2, Real)>,
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
            tf_static_topic: "/tf_static".into(),
            pose_topic: None,
            scan_mount: None,
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
/// A scan or a map pose is matched to an odometry pose at most this far from its stamp (s).
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
    /// Transforms accepted (map→odom and the robot's own frames).
    pub tf: AtomicU64,
    /// Map poses accepted from the pose topic.
    pub poses: AtomicU64,
    /// Plans held (the robot stands) because no transform led from the newest scan's frame
    /// to the base yet: a scan placed anywhere but at its scanner would show the world moved
    /// or mirrored.
    pub scans_unplaced: AtomicU64,
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
    /// map → odom (x, y, yaw), from `/tf` or the pose topic.
    map_from_odom: Option<(Vec2, Real)>,
    /// The robot's own frames: child → (parent, offset, yaw), from `/tf` and `/tf_static`.
    frames: BTreeMap<String, (String, Vec2, Real)>,
    /// A transform came on `/tf_static`.
    static_seen: bool,
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
    /// The newest scan, placed at the robot's pose; `None` also while it cannot be placed.
    pub scan: Option<Scan>,
    /// How long ago the odometry behind `ego` arrived.
    pub odom_age: Duration,
    /// The scan's frame and where it sits on the base, or `None` when no transform led from
    /// it to the base (the scan is then not used, and the robot holds).
    pub scan_mount: Option<(String, Option<(Vec2, Real)>)>,
}

impl Sensed {
    /// A scan came whose frame has no transform to the base yet: the robot cannot know where
    /// its scanner looks, so it must not move.
    #[must_use]
    pub fn scanner_unplaced(&self) -> bool {
        matches!(self.scan_mount, Some((_, None)))
    }
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
    /// The scanner mounting last logged: its frame, offset and yaw.
    logged_mount: Mutex<Option<(String, Vec2, Real)>>,
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
        // map→odom from /tf unless a pose topic gives it.
        let map_from_tf = config.pose_topic.is_none();
        let tf_map_frame = map_frame.clone();
        sub!(
            TFMessage,
            &config.tf_topic,
            Qos::DEFAULT_10,
            move |l: &mut Latest, m: TFMessage, c: &RosCounters| {
                take_transforms(l, &m, &tf_map_frame, map_from_tf, c);
            }
        );
        let static_map_frame = map_frame.clone();
        sub!(
            TFMessage,
            &config.tf_static_topic,
            Qos::TF_STATIC,
            move |l: &mut Latest, m: TFMessage, c: &RosCounters| {
                l.static_seen = true;
                take_transforms(l, &m, &static_map_frame, map_from_tf, c);
            }
        );
        if let Some(pose_topic) = &config.pose_topic {
            let pose_map_frame = map_frame.clone();
            sub!(
                PoseWithCovarianceStamped,
                pose_topic,
                Qos::DEFAULT_10,
                move |l: &mut Latest, m: PoseWithCovarianceStamped, c: &RosCounters| {
                    take_map_pose(l, &m, &pose_map_frame, c);
                }
            );
        }
        // /tf_static is transient local: what its publishers sent before this node came is in
        // their caches (rmw_zenoh's AdvancedPublisher), asked for until one answers.
        let static_fq = graph::fully_qualified(&namespace, &config.tf_static_topic)?;
        tokio::spawn(ask_static_history(
            session.clone(),
            graph::history_key(&graph::topic_key::<TFMessage>(
                config.domain_id,
                &static_fq,
                d,
            )),
            Arc::downgrade(&latest),
            counters.clone(),
            map_frame.clone(),
            map_from_tf,
        ));
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
            logged_mount: Mutex::new(None),
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
    /// until fresh odometry (and, if the odometry frame is not the map frame, map→odom) came,
    /// and while the newest scan's frame has no transform to the base (as Nav2's collision
    /// monitor stops without valid sensor data, the robot then stands).
    pub fn sensed(&self) -> Option<Sensed> {
        let l = self.latest.lock().unwrap_or_else(|e| e.into_inner());
        let (_, at) = l.odom.as_ref()?;
        let odom_age = at.elapsed();
        if odom_age > self.config.odom_timeout {
            return None;
        }
        let sensed = sense(&l, &self.config).map(|s| Sensed { odom_age, ..s })?;
        drop(l);
        if let Some((frame, mount)) = &sensed.scan_mount {
            self.log_mount(frame, *mount);
        }
        (!sensed.scanner_unplaced()).then_some(sensed)
    }

    /// Logs where the scanner sits whenever that changes, and counts (logging at powers of
    /// ten) plans held for want of the scanner's transform.
    fn log_mount(&self, frame: &str, mount: Option<(Vec2, Real)>) {
        let Some((offset, yaw)) = mount else {
            let n = self.counters.scans_unplaced.fetch_add(1, Ordering::Relaxed) + 1;
            if log_now(n) {
                tracing::warn!(
                    frame,
                    scans = n,
                    "no transform from the scan's frame to the base yet (/tf_static): the robot \
                     holds until its scanner is placed"
                );
            }
            return;
        };
        // Compared as values, so that a plan allocates nothing while the mounting holds.
        let mut logged = self.logged_mount.lock().unwrap_or_else(|e| e.into_inner());
        let same = logged
            .as_ref()
            .is_some_and(|(f, o, y)| f == frame && *o == offset && *y == yaw);
        if !same {
            tracing::info!(
                "scanner mounted: {frame} at ({:.3}, {:.3}) m, {:.3} rad",
                offset.x,
                offset.y,
                yaw
            );
            *logged = Some((frame.to_owned(), offset, yaw));
        }
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
    // The scan is placed at the odometry pose nearest its stamp (a scan with no pose within
    // SCAN_POSE_TOLERANCE_S of its stamp is not used), and at the scanner's mounting on the
    // base: the flag's, or the transforms' from its frame to odometry's child frame (without
    // one it is not used at all).
    let base = match odom.child_frame_id.trim_start_matches('/') {
        "" => "base_link",
        frame => frame,
    };
    let mut scan_mount = None;
    let scan = l.scan.as_ref().and_then(|s| {
        let (position, yaw) = pose_at(&l.poses, s.header.stamp.as_secs())?;
        let frame = s.header.frame_id.trim_start_matches('/');
        let mount = config.scan_mount.or_else(|| {
            if frame.is_empty() || frame == base {
                Some((Vec2::zeros(), 0.0))
            } else {
                mount_of(&l.frames, frame, base)
            }
        });
        scan_mount = Some((frame.to_owned(), mount));
        let (offset, mount_yaw) = mount?;
        Some(Scan {
            origin: to_map(position + rotate(offset, yaw)),
            bearing0: yaw + rotation + mount_yaw + Real::from(s.angle_min),
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
        scan_mount,
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
mod tests;
