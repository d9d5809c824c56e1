//! The ROS 2 messages an agent reads from and writes to a robot, field for field as their
//! `.msg` definitions give them (Jazzy's `common_interfaces`; `people_msgs` from the ROS `people`
//! stack), with their CDR encoding and the checks a decoded message must pass.
//!
//! [`decode`] is the only way in from the network: the type's [`Limits`], the CDR structure,
//! then [`Message::check`]: finite numbers and physical bounds. Laser ranges are the exception:
//! REP 117 gives `+inf`, `-inf` and NaN meanings (no return, too close, no measurement), so they
//! pass through and the consumer reads them as such.

use crate::cdr::{CdrError, Limits, Reader, Writer};

/// A value with a CDR encoding.
pub trait Cdr: Sized {
    /// The fewest bytes one value takes on the wire (bounds sequence lengths before allocation).
    const MIN_BYTES: usize;
    /// Appends the value.
    fn write(&self, w: &mut Writer);
    /// Reads a value; `field` names it in errors.
    fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, CdrError>;
}

/// A ROS 2 message type.
pub trait Message: Cdr {
    /// Its ROS name, `package/msg/Type`.
    const NAME: &'static str;
    /// Its REP-2016 type hash (Jazzy and Kilted; the same in both for every type here), as
    /// rosbags computes it (`fixtures/make_fixtures.py` checks each).
    const RIHS01: &'static str;
    /// Size limits for decoding it.
    const LIMITS: Limits;
    /// Finite and physical bounds of a decoded value.
    fn check(&self) -> Result<(), CdrError>;
}

/// The message's CDR payload, header included.
pub fn encode<M: Message>(message: &M) -> Vec<u8> {
    let mut w = Writer::new();
    message.write(&mut w);
    w.into_bytes()
}

/// Decodes untrusted bytes: limits, structure, then [`Message::check`].
pub fn decode<M: Message>(bytes: &[u8]) -> Result<M, CdrError> {
    let mut r = Reader::new(bytes, M::LIMITS)?;
    let message = M::read(&mut r, M::NAME)?;
    r.finish()?;
    message.check()?;
    Ok(message)
}

/// The DDS type name rmw_zenoh puts in key expressions: `package::msg::dds_::Type_`.
pub fn dds_type_name(ros_name: &str) -> String {
    match ros_name.rsplit_once('/') {
        Some((package_and_kind, ty)) => {
            format!("{}::dds_::{ty}_", package_and_kind.replace('/', "::"))
        }
        None => format!("{ros_name}_"),
    }
}

macro_rules! primitive {
    ($ty:ty, $size:expr, $write:ident, $read:ident) => {
        impl Cdr for $ty {
            const MIN_BYTES: usize = $size;
            fn write(&self, w: &mut Writer) {
                w.$write(*self);
            }
            fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, CdrError> {
                r.$read(field)
            }
        }
    };
}
primitive!(u8, 1, u8, u8);
primitive!(u32, 4, u32, u32);
primitive!(i32, 4, i32, i32);
primitive!(f32, 4, f32, f32);
primitive!(f64, 8, f64, f64);

impl Cdr for String {
    const MIN_BYTES: usize = 5;
    fn write(&self, w: &mut Writer) {
        w.string(self);
    }
    fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, CdrError> {
        r.string(field)
    }
}

impl<T: Cdr> Cdr for Vec<T> {
    const MIN_BYTES: usize = 4;
    fn write(&self, w: &mut Writer) {
        w.len(self.len());
        for item in self {
            item.write(w);
        }
    }
    fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, CdrError> {
        let n = r.len(field, T::MIN_BYTES)?;
        (0..n).map(|_| T::read(r, field)).collect()
    }
}

/// Declares a struct of CDR fields, written and read in declaration order.
macro_rules! cdr_struct {
    ($(#[$meta:meta])* $name:ident { $($(#[$fmeta:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Default)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty),*
        }
        impl Cdr for $name {
            const MIN_BYTES: usize = 0 $(+ <$ty as Cdr>::MIN_BYTES)*;
            fn write(&self, w: &mut Writer) {
                $(self.$field.write(w);)*
            }
            fn read(r: &mut Reader<'_>, _field: &'static str) -> Result<Self, CdrError> {
                Ok(Self { $($field: <$ty as Cdr>::read(r, stringify!($field))?),* })
            }
        }
    };
}

/// A 6 × 6 row-major covariance (`float64[36]`, a fixed array: no length on the wire).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Self([0.0; 36])
    }
}

impl Cdr for Covariance {
    const MIN_BYTES: usize = 36 * 8;
    fn write(&self, w: &mut Writer) {
        for &x in &self.0 {
            w.f64(x);
        }
    }
    fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, CdrError> {
        let mut c = [0.0; 36];
        for x in &mut c {
            *x = r.f64(field)?;
        }
        Ok(Self(c))
    }
}

cdr_struct!(
    /// `builtin_interfaces/msg/Time`.
    Time {
        /// Seconds.
        sec: i32,
        /// Nanoseconds, below 10⁹.
        nanosec: u32,
    }
);

impl Time {
    /// The time `seconds` after the epoch (negative times clamp to 0).
    pub fn from_secs(seconds: f64) -> Self {
        let s = seconds.max(0.0);
        let sec = s.floor().min(f64::from(i32::MAX));
        let nanosec = (((s - sec) * 1e9).round() as u32).min(999_999_999);
        Self {
            sec: sec as i32,
            nanosec,
        }
    }

    /// Seconds since the epoch.
    pub fn as_secs(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

cdr_struct!(
    /// `std_msgs/msg/Header`.
    Header {
        /// When the data was taken.
        stamp: Time,
        /// The frame the data is in.
        frame_id: String,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/Vector3` (and `Point`, which has the same fields).
    Vector3 {
        /// x.
        x: f64,
        /// y.
        y: f64,
        /// z.
        z: f64,
    }
);

/// `geometry_msgs/msg/Point`: the same wire shape as [`Vector3`].
pub type Point = Vector3;

cdr_struct!(
    /// `geometry_msgs/msg/Quaternion`.
    Quaternion {
        /// x.
        x: f64,
        /// y.
        y: f64,
        /// z.
        z: f64,
        /// w.
        w: f64,
    }
);

impl Quaternion {
    /// A rotation by `yaw` about z.
    pub fn from_yaw(yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The rotation's yaw (about z), for a normalised quaternion.
    pub fn yaw(&self) -> f64 {
        let siny = 2.0 * (self.w * self.z + self.x * self.y);
        let cosy = 1.0 - 2.0 * (self.y * self.y + self.z * self.z);
        siny.atan2(cosy)
    }
}

cdr_struct!(
    /// `geometry_msgs/msg/Pose`.
    Pose {
        /// Position.
        position: Point,
        /// Orientation.
        orientation: Quaternion,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/PoseWithCovariance`.
    PoseWithCovariance {
        /// Pose.
        pose: Pose,
        /// Its covariance (x, y, z, roll, pitch, yaw).
        covariance: Covariance,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/Twist`.
    Twist {
        /// Linear velocity, m/s.
        linear: Vector3,
        /// Angular velocity, rad/s.
        angular: Vector3,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/TwistWithCovariance`.
    TwistWithCovariance {
        /// Twist.
        twist: Twist,
        /// Its covariance.
        covariance: Covariance,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/TwistStamped` (Nav2's `cmd_vel` type since Jazzy).
    TwistStamped {
        /// Stamp and frame.
        header: Header,
        /// Twist.
        twist: Twist,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/PoseWithCovarianceStamped` (AMCL's `amcl_pose`).
    PoseWithCovarianceStamped {
        /// Stamp and frame.
        header: Header,
        /// Pose.
        pose: PoseWithCovariance,
    }
);

cdr_struct!(
    /// `nav_msgs/msg/Odometry`.
    Odometry {
        /// Stamp and the pose's frame (odom).
        header: Header,
        /// The twist's frame (the base).
        child_frame_id: String,
        /// Pose in `header.frame_id`.
        pose: PoseWithCovariance,
        /// Twist in `child_frame_id`.
        twist: TwistWithCovariance,
    }
);

cdr_struct!(
    /// `sensor_msgs/msg/LaserScan`.
    LaserScan {
        /// Stamp of the first ray and the scanner's frame.
        header: Header,
        /// Angle of the first ray, rad.
        angle_min: f32,
        /// Angle of the last ray, rad.
        angle_max: f32,
        /// Angle between rays, rad.
        angle_increment: f32,
        /// Time between rays, s.
        time_increment: f32,
        /// Time between scans, s.
        scan_time: f32,
        /// Shortest valid range, m.
        range_min: f32,
        /// Longest valid range, m.
        range_max: f32,
        /// Ranges, m (REP 117: +inf no return, -inf too close, NaN no measurement).
        ranges: Vec<f32>,
        /// Intensities (device units), empty or one per range.
        intensities: Vec<f32>,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/Transform`.
    Transform {
        /// Translation, m.
        translation: Vector3,
        /// Rotation.
        rotation: Quaternion,
    }
);

cdr_struct!(
    /// `geometry_msgs/msg/TransformStamped`.
    TransformStamped {
        /// Stamp and the parent frame.
        header: Header,
        /// The child frame.
        child_frame_id: String,
        /// The child's pose in the parent frame.
        transform: Transform,
    }
);

cdr_struct!(
    /// `tf2_msgs/msg/TFMessage` (`/tf`, `/tf_static`).
    TFMessage {
        /// Transforms.
        transforms: Vec<TransformStamped>,
    }
);

cdr_struct!(
    /// `people_msgs/msg/Person`.
    Person {
        /// Track name or id.
        name: String,
        /// Position in the header's frame, m.
        position: Point,
        /// Velocity, m/s.
        velocity: Point,
        /// Tracker's confidence.
        reliability: f64,
        /// Tag names.
        tagnames: Vec<String>,
        /// Tag values, one per name.
        tags: Vec<String>,
    }
);

cdr_struct!(
    /// `people_msgs/msg/People`: tracked people, as Nav2's social-costmap plugins read them.
    People {
        /// Stamp and frame of every person.
        header: Header,
        /// People.
        people: Vec<Person>,
    }
);

/// Farther than this from a frame's origin is not a place on a site, m.
pub const MAX_COORDINATE_M: f64 = 1.0e5;
/// Faster than this is not a ground robot's or a person's motion, m/s.
pub const MAX_SPEED_M_S: f64 = 20.0;
/// Faster than this is not a ground robot's turn, rad/s.
pub const MAX_TURN_RATE_RAD_S: f64 = 20.0;
/// A rotation quaternion's norm may stray this far from 1 (publishers' rounding).
pub const QUATERNION_NORM_TOLERANCE: f64 = 1.0e-2;

fn bounded(field: &'static str, v: f64, limit: f64) -> Result<(), CdrError> {
    if !v.is_finite() {
        Err(CdrError::OutOfBounds {
            field,
            why: "not finite",
        })
    } else if v.abs() > limit {
        Err(CdrError::OutOfBounds {
            field,
            why: "beyond its physical bound",
        })
    } else {
        Ok(())
    }
}

impl Header {
    fn check(&self) -> Result<(), CdrError> {
        if self.stamp.nanosec >= 1_000_000_000 {
            return Err(CdrError::OutOfBounds {
                field: "stamp.nanosec",
                why: "not below 10^9",
            });
        }
        Ok(())
    }
}

impl Vector3 {
    fn check(&self, field: &'static str, limit: f64) -> Result<(), CdrError> {
        bounded(field, self.x, limit)?;
        bounded(field, self.y, limit)?;
        bounded(field, self.z, limit)
    }

    /// Length of the x–y part.
    pub fn planar_norm(&self) -> f64 {
        self.x.hypot(self.y)
    }
}

impl Quaternion {
    fn check(&self, field: &'static str) -> Result<(), CdrError> {
        let norm = (self.x * self.x + self.y * self.y + self.z * self.z + self.w * self.w).sqrt();
        if !norm.is_finite() || (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
            return Err(CdrError::OutOfBounds {
                field,
                why: "not a unit quaternion",
            });
        }
        Ok(())
    }
}

impl Pose {
    fn check(&self) -> Result<(), CdrError> {
        self.position.check("pose.position", MAX_COORDINATE_M)?;
        self.orientation.check("pose.orientation")
    }
}

impl Twist {
    fn check_bounds(&self) -> Result<(), CdrError> {
        self.linear.check("twist.linear", MAX_SPEED_M_S)?;
        self.angular.check("twist.angular", MAX_TURN_RATE_RAD_S)
    }
}

impl Transform {
    fn check(&self) -> Result<(), CdrError> {
        self.translation
            .check("transform.translation", MAX_COORDINATE_M)?;
        self.rotation.check("transform.rotation")
    }
}

const SMALL: Limits = Limits {
    max_bytes: 4 * 1024,
    max_sequence: 0,
    max_string: 256,
};

impl Message for Twist {
    const NAME: &'static str = "geometry_msgs/msg/Twist";
    const RIHS01: &'static str =
        "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a";
    const LIMITS: Limits = Limits {
        max_bytes: 64,
        ..SMALL
    };
    fn check(&self) -> Result<(), CdrError> {
        self.check_bounds()
    }
}

impl Message for TwistStamped {
    const NAME: &'static str = "geometry_msgs/msg/TwistStamped";
    const RIHS01: &'static str =
        "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64";
    const LIMITS: Limits = SMALL;
    fn check(&self) -> Result<(), CdrError> {
        self.header.check()?;
        self.twist.check_bounds()
    }
}

impl Message for Odometry {
    const NAME: &'static str = "nav_msgs/msg/Odometry";
    const RIHS01: &'static str =
        "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0";
    const LIMITS: Limits = SMALL;
    fn check(&self) -> Result<(), CdrError> {
        self.header.check()?;
        self.pose.pose.check()?;
        self.twist.twist.check_bounds()
    }
}

impl Message for PoseWithCovarianceStamped {
    const NAME: &'static str = "geometry_msgs/msg/PoseWithCovarianceStamped";
    const RIHS01: &'static str =
        "RIHS01_26432f9803e43727d3c8f668d1fdb3c630f548af631e2f4e31382371bfea3b6e";
    const LIMITS: Limits = SMALL;
    fn check(&self) -> Result<(), CdrError> {
        self.header.check()?;
        self.pose.pose.check()
    }
}

impl Message for LaserScan {
    const NAME: &'static str = "sensor_msgs/msg/LaserScan";
    const RIHS01: &'static str =
        "RIHS01_64c191398013af96509d518dac71d5164f9382553fce5c1f8cca5be7924bd828";
    /// 65,536 rays with intensities (a 2D scanner gives a few thousand).
    const LIMITS: Limits = Limits {
        max_bytes: 2 * 4 * 65_536 + 1024,
        max_sequence: 65_536,
        max_string: 256,
    };
    fn check(&self) -> Result<(), CdrError> {
        self.header.check()?;
        // A full turn may start anywhere in [−2π, 2π] and so end below 4π.
        let two_turns = 4.0 * std::f64::consts::PI + 1e-3;
        bounded("angle_min", f64::from(self.angle_min), two_turns)?;
        bounded("angle_max", f64::from(self.angle_max), two_turns)?;
        bounded(
            "angle_increment",
            f64::from(self.angle_increment),
            two_turns,
        )?;
        if self.angle_increment == 0.0 && self.ranges.len() > 1 {
            return Err(CdrError::OutOfBounds {
                field: "angle_increment",
                why: "zero",
            });
        }
        bounded("range_min", f64::from(self.range_min), MAX_COORDINATE_M)?;
        bounded("range_max", f64::from(self.range_max), MAX_COORDINATE_M)?;
        if self.range_min < 0.0 || self.range_max < self.range_min {
            return Err(CdrError::OutOfBounds {
                field: "range_max",
                why: "not ≥ range_min ≥ 0",
            });
        }
        if !self.intensities.is_empty() && self.intensities.len() != self.ranges.len() {
            return Err(CdrError::OutOfBounds {
                field: "intensities",
                why: "neither empty nor one per range",
            });
        }
        Ok(())
    }
}

impl Message for TFMessage {
    const NAME: &'static str = "tf2_msgs/msg/TFMessage";
    const RIHS01: &'static str =
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087";
    const LIMITS: Limits = Limits {
        max_bytes: 256 * 1024,
        max_sequence: 512,
        max_string: 256,
    };
    fn check(&self) -> Result<(), CdrError> {
        for t in &self.transforms {
            t.header.check()?;
            t.transform.check()?;
        }
        Ok(())
    }
}

impl Message for People {
    const NAME: &'static str = "people_msgs/msg/People";
    const RIHS01: &'static str =
        "RIHS01_9ea98a5e58f833a9532957bca23a6b8006a12885d5a16c8ca41dd901d10c33b6";
    const LIMITS: Limits = Limits {
        max_bytes: 512 * 1024,
        max_sequence: 1024,
        max_string: 256,
    };
    fn check(&self) -> Result<(), CdrError> {
        self.header.check()?;
        for p in &self.people {
            p.position.check("person.position", MAX_COORDINATE_M)?;
            p.velocity.check("person.velocity", MAX_SPEED_M_S)?;
            bounded("person.reliability", p.reliability, 1.0e6)?;
            if p.tagnames.len() != p.tags.len() {
                return Err(CdrError::OutOfBounds {
                    field: "person.tags",
                    why: "not one per tag name",
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dds_type_names_follow_rmw_zenoh() {
        assert_eq!(
            dds_type_name("geometry_msgs/msg/Twist"),
            "geometry_msgs::msg::dds_::Twist_"
        );
        assert_eq!(
            dds_type_name("people_msgs/msg/People"),
            "people_msgs::msg::dds_::People_"
        );
    }

    #[test]
    fn time_splits_seconds() {
        let t = Time::from_secs(12.25);
        assert_eq!(
            t,
            Time {
                sec: 12,
                nanosec: 250_000_000
            }
        );
        assert!((t.as_secs() - 12.25).abs() < 1e-12);
        assert!(Time::from_secs(0.999_999_999_9).nanosec < 1_000_000_000);
    }

    #[test]
    fn yaw_round_trips_through_a_quaternion() {
        for yaw in [-3.0, -1.0, 0.0, 0.5, 3.1] {
            assert!((Quaternion::from_yaw(yaw).yaw() - yaw).abs() < 1e-12);
        }
    }

    #[test]
    fn checks_refuse_what_no_robot_sends() {
        let mut twist = Twist::default();
        twist.linear.x = f64::NAN;
        assert!(decode::<Twist>(&encode(&twist)).is_err());
        twist.linear.x = 1e9;
        assert!(decode::<Twist>(&encode(&twist)).is_err());
        let odom = Odometry::default();
        // The default quaternion is all zeros: no rotation at all.
        assert_eq!(
            decode::<Odometry>(&encode(&odom)),
            Err(CdrError::OutOfBounds {
                field: "pose.orientation",
                why: "not a unit quaternion"
            })
        );
        let mut scan = LaserScan {
            angle_increment: 0.01,
            range_max: 10.0,
            ..Default::default()
        };
        scan.ranges = vec![1.0, f32::INFINITY, f32::NAN];
        assert_eq!(
            decode::<LaserScan>(&encode(&scan)).map(|s| s.ranges.len()),
            Ok(3)
        );
        scan.intensities = vec![1.0];
        assert!(decode::<LaserScan>(&encode(&scan)).is_err());
    }
}
