//! How rmw_zenoh names things on Zenoh: topic key expressions, the liveliness tokens that put a
//! node and its publishers and subscriptions in the ROS graph (`ros2 node list`,
//! `ros2 topic info`), the QoS string inside them, and the attachment every sample carries.
//!
//! The formats are those of rmw_zenoh's `docs/design.md` and `liveliness_utils.cpp` as released in
//! rmw_zenoh_cpp 0.2.4 and later (Jazzy), 0.6 and later (Kilted, Rolling) and 0.1.2 and later
//! (Humble). Those releases carry the attachment as 33 fixed bytes; earlier ones wrote it as
//! named fields with Zenoh's serializer and do not interoperate with this crate.

use crate::msg::{Message, dds_type_name};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// The hermetic prefix of every liveliness token.
pub const ADMIN_SPACE: &str = "@ros2_lv";
/// Length of a publisher's or client's GID.
pub const GID_LEN: usize = 16;
/// Length of an attachment: sequence number, timestamp, GID length, GID.
pub const ATTACHMENT_LEN: usize = 8 + 8 + 1 + GID_LEN;

/// The ROS 2 distribution a robot runs: it decides the type hash in every key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Distro {
    /// Humble: no type hashes (`TypeHashNotSupported`).
    Humble,
    /// Jazzy: REP-2016 RIHS01 type hashes.
    #[default]
    Jazzy,
    /// Kilted: as Jazzy (the hashes of the types here are the same).
    Kilted,
}

impl Distro {
    /// The type hash chunk of `M`'s keys on this distribution.
    pub fn type_hash<M: Message>(self) -> &'static str {
        match self {
            Distro::Humble => "TypeHashNotSupported",
            Distro::Jazzy | Distro::Kilted => M::RIHS01,
        }
    }
}

impl FromStr for Distro {
    type Err = NameError;
    fn from_str(s: &str) -> Result<Self, NameError> {
        match s.to_ascii_lowercase().as_str() {
            "humble" => Ok(Distro::Humble),
            "jazzy" => Ok(Distro::Jazzy),
            "kilted" => Ok(Distro::Kilted),
            _ => Err(NameError::Distro(s.to_owned())),
        }
    }
}

impl fmt::Display for Distro {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Distro::Humble => "humble",
            Distro::Jazzy => "jazzy",
            Distro::Kilted => "kilted",
        })
    }
}

/// A name ROS 2 would not accept.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum NameError {
    /// A namespace or topic name with characters or tokens ROS 2 forbids.
    #[error(
        "`{0}` is not a valid ROS 2 name (tokens of letters, digits and underscores, separated by single /, not starting with a digit)"
    )]
    Name(String),
    /// A node name that is not one token.
    #[error(
        "`{0}` is not a valid ROS 2 node name (letters, digits and underscores, not starting with a digit)"
    )]
    Node(String),
    /// An unknown distribution.
    #[error("unknown ROS 2 distribution `{0}` (humble, jazzy or kilted)")]
    Distro(String),
}

fn valid_token(t: &str) -> bool {
    !t.is_empty()
        && !t.starts_with(|c: char| c.is_ascii_digit())
        && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !t.contains("__")
}

/// A namespace, normalised to `/a/b` (or `/` for none).
pub fn namespace(ns: &str) -> Result<String, NameError> {
    let trimmed = ns.trim_matches('/');
    if trimmed.is_empty() {
        return Ok("/".to_owned());
    }
    if !trimmed.split('/').all(valid_token) {
        return Err(NameError::Name(ns.to_owned()));
    }
    Ok(format!("/{trimmed}"))
}

/// The fully qualified name of `topic` in namespace `ns` (`/`-rooted topics ignore it).
pub fn fully_qualified(ns: &str, topic: &str) -> Result<String, NameError> {
    let ns = namespace(ns)?;
    let rel = topic.strip_prefix('/');
    let body = rel.unwrap_or(topic);
    if body.is_empty() || body.ends_with('/') || !body.split('/').all(valid_token) {
        return Err(NameError::Name(topic.to_owned()));
    }
    Ok(match (rel, ns.as_str()) {
        (Some(_), _) | (None, "/") => format!("/{body}"),
        (None, ns) => format!("{ns}/{body}"),
    })
}

/// Checks a node name.
pub fn node_name(name: &str) -> Result<&str, NameError> {
    if valid_token(name) {
        Ok(name)
    } else {
        Err(NameError::Node(name.to_owned()))
    }
}

/// A name with every `/` replaced by `%` (`%` alone for an empty or root name).
pub fn mangle(name: &str) -> String {
    let trimmed = if name == "/" { "" } else { name };
    if trimmed.is_empty() {
        "%".to_owned()
    } else {
        trimmed.replace('/', "%")
    }
}

/// The data key of `M` on `fq_topic`: `<domain>/<topic without leading />/<dds type>/<hash>`.
pub fn topic_key<M: Message>(domain_id: u32, fq_topic: &str, distro: Distro) -> String {
    format!(
        "{domain_id}/{}/{}/{}",
        fq_topic.trim_start_matches('/'),
        dds_type_name(M::NAME),
        distro.type_hash::<M>()
    )
}

/// Where a transient-local topic's history is served: rmw_zenoh (since rmw_zenoh#368,
/// February 2025) publishes such a topic through a Zenoh `AdvancedPublisher` whose cache
/// answers queries on `<topic key>/@adv/**`, replying with samples on the topic key itself.
/// A late subscriber gets the publishers' cached samples by querying this key with any reply
/// key accepted, as zenoh-ext's `AdvancedSubscriber` does for its history.
pub fn history_key(topic_key: &str) -> String {
    format!("{topic_key}/@adv/**")
}

/// Reliability (rmw's enum values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    /// Delivered over a reliable transport (rmw_zenoh's default).
    Reliable = 1,
    /// May drop.
    BestEffort = 2,
}

/// Durability (rmw's enum values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    /// Late joiners get the publisher's cache.
    TransientLocal = 1,
    /// Only live samples (rmw_zenoh's default since 0.2.2 on Jazzy).
    Volatile = 2,
}

/// A QoS profile, as far as the graph shows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Reliability.
    pub reliability: Reliability,
    /// Durability.
    pub durability: Durability,
    /// Keep-last depth (`None`: keep all).
    pub depth: Option<u32>,
}

impl Qos {
    /// rmw_zenoh's default: reliable, volatile, keep last 42.
    pub const RMW_ZENOH_DEFAULT: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::Volatile,
        depth: Some(42),
    };
    /// `rclcpp::SensorDataQoS`: best effort, volatile, keep last 5.
    pub const SENSOR_DATA: Qos = Qos {
        reliability: Reliability::BestEffort,
        durability: Durability::Volatile,
        depth: Some(5),
    };
    /// `rclcpp::QoS(10)`, what most publishers and subscriptions ask for.
    pub const DEFAULT_10: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::Volatile,
        depth: Some(10),
    };
    /// tf2_ros's static listener (`StaticListenerQoS`): reliable, transient local, keep last
    /// 100.
    pub const TF_STATIC: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::TransientLocal,
        depth: Some(100),
    };

    /// The compact form in liveliness tokens (rmw_zenoh's `qos_to_keyexpr`): each field empty
    /// where it equals rmw_zenoh's default; deadline, lifespan and liveliness are always the
    /// defaults here (infinite, automatic).
    pub fn to_keyexpr(&self) -> String {
        let d = Self::RMW_ZENOH_DEFAULT;
        let field = |same: bool, v: u32| if same { String::new() } else { v.to_string() };
        let reliability = field(self.reliability == d.reliability, self.reliability as u32);
        let durability = field(self.durability == d.durability, self.durability as u32);
        let (history, depth) = match self.depth {
            Some(n) => (String::new(), field(Some(n) == d.depth, n)),
            None => ("2".to_owned(), String::new()),
        };
        format!("{reliability}:{durability}:{history},{depth}:,:,:,,")
    }
}

/// Kinds of graph entity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntityKind {
    /// A message publisher.
    Publisher,
    /// A message subscription.
    Subscription,
}

impl EntityKind {
    fn code(self) -> &'static str {
        match self {
            EntityKind::Publisher => "MP",
            EntityKind::Subscription => "MS",
        }
    }
}

/// A node in the ROS graph: where its tokens say it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Node {
    /// `ROS_DOMAIN_ID`.
    pub domain_id: u32,
    /// The Zenoh session id, as the session prints it.
    pub session_id: String,
    /// The node's id within the session.
    pub node_id: u32,
    /// Normalised namespace (`/` for none).
    pub namespace: String,
    /// Node name.
    pub name: String,
}

impl Node {
    /// The node's liveliness token.
    pub fn token(&self) -> String {
        format!(
            "{ADMIN_SPACE}/{}/{}/{id}/{id}/NN/%/{}/{}",
            self.domain_id,
            self.session_id,
            mangle(&self.namespace),
            self.name,
            id = self.node_id,
        )
    }

    /// The liveliness token of its publisher or subscription `entity_id` of `M` on `fq_topic`.
    pub fn endpoint_token<M: Message>(
        &self,
        entity_id: u32,
        kind: EntityKind,
        fq_topic: &str,
        distro: Distro,
        qos: Qos,
    ) -> String {
        format!(
            "{ADMIN_SPACE}/{}/{}/{}/{entity_id}/{}/%/{}/{}/{}/{}/{}/{}",
            self.domain_id,
            self.session_id,
            self.node_id,
            kind.code(),
            mangle(&self.namespace),
            self.name,
            mangle(fq_topic),
            dds_type_name(M::NAME),
            distro.type_hash::<M>(),
            qos.to_keyexpr(),
        )
    }
}

/// What rmw_zenoh attaches to every sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// The publisher's sequence number (from 1).
    pub sequence: i64,
    /// Source time, ns since the Unix epoch.
    pub timestamp_ns: i64,
    /// The publisher's GID.
    pub gid: [u8; GID_LEN],
}

/// An attachment that is not rmw_zenoh's 33 bytes.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("attachment of {len} bytes is not rmw_zenoh's (8 + 8 + 1 + 16, GID length 16)")]
pub struct AttachmentError {
    /// Its length.
    pub len: usize,
}

impl Attachment {
    /// Little-endian sequence number, timestamp, GID length, GID.
    pub fn to_bytes(&self) -> [u8; ATTACHMENT_LEN] {
        let mut b = [0u8; ATTACHMENT_LEN];
        b[..8].copy_from_slice(&self.sequence.to_le_bytes());
        b[8..16].copy_from_slice(&self.timestamp_ns.to_le_bytes());
        b[16] = GID_LEN as u8;
        b[17..].copy_from_slice(&self.gid);
        b
    }

    /// Parses an attachment from untrusted bytes.
    pub fn from_bytes(b: &[u8]) -> Result<Self, AttachmentError> {
        let err = AttachmentError { len: b.len() };
        let fixed: &[u8; ATTACHMENT_LEN] = b.try_into().map_err(|_| err.clone())?;
        if usize::from(fixed[16]) != GID_LEN {
            return Err(err);
        }
        let (seq, rest) = fixed.split_first_chunk::<8>().ok_or(err.clone())?;
        let (ts, rest) = rest.split_first_chunk::<8>().ok_or(err.clone())?;
        let gid: [u8; GID_LEN] = rest[1..].try_into().map_err(|_| err)?;
        Ok(Self {
            sequence: i64::from_le_bytes(*seq),
            timestamp_ns: i64::from_le_bytes(*ts),
            gid,
        })
    }
}

/// A GID for an entity: 16 bytes of a 128-bit FNV-1a hash of its liveliness token, so that two
/// entities in the graph never share one.
pub fn gid_of(token: &str) -> [u8; GID_LEN] {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let hash = token
        .bytes()
        .fold(OFFSET, |h, b| (h ^ u128::from(b)).wrapping_mul(PRIME));
    hash.to_le_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::Twist;

    #[test]
    fn names_are_qualified_and_checked() {
        assert_eq!(fully_qualified("", "cmd_vel"), Ok("/cmd_vel".into()));
        assert_eq!(
            fully_qualified("/robot1", "cmd_vel"),
            Ok("/robot1/cmd_vel".into())
        );
        assert_eq!(fully_qualified("robot1/", "/tf"), Ok("/tf".into()));
        assert_eq!(fully_qualified("/a/b", "scan"), Ok("/a/b/scan".into()));
        for bad in ["", "1scan", "sc an", "a//b", "scan/", "a__b"] {
            assert!(fully_qualified("/r", bad).is_err(), "{bad}");
        }
        assert!(namespace("/robot-1").is_err());
        assert!(node_name("gapfleet_agent").is_ok());
        assert!(node_name("a/b").is_err());
    }

    #[test]
    fn keys_and_tokens_match_the_design_document() {
        // design.md: `0/robot1/chatter/std_msgs::msg::dds_::String_/RIHS01_…` and the tokens
        // `@ros2_lv/2/<zid>/0/0/NN/%/%/listener`, `…/0/10/MS/%/%/listener/%chatter/<type>/<hash>/<qos>`.
        let key = topic_key::<Twist>(0, "/robot1/cmd_vel", Distro::Jazzy);
        assert_eq!(
            key,
            "0/robot1/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
        );
        assert_eq!(
            topic_key::<Twist>(3, "/cmd_vel", Distro::Humble),
            "3/cmd_vel/geometry_msgs::msg::dds_::Twist_/TypeHashNotSupported"
        );
        let node = Node {
            domain_id: 2,
            session_id: "aac3178e146ba6f1fc6e6a4085e77f21".into(),
            node_id: 0,
            namespace: "/".into(),
            name: "listener".into(),
        };
        assert_eq!(
            node.token(),
            "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
        );
        let sub = node.endpoint_token::<Twist>(
            10,
            EntityKind::Subscription,
            "/chatter",
            Distro::Humble,
            Qos::DEFAULT_10,
        );
        assert_eq!(
            sub,
            "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/geometry_msgs::msg::dds_::Twist_/TypeHashNotSupported/::,10:,:,:,,"
        );
        let ns = Node {
            namespace: "/robot1".into(),
            ..node
        };
        assert!(ns.token().ends_with("/NN/%/%robot1/listener"));
    }

    #[test]
    fn qos_strings_follow_qos_to_keyexpr() {
        assert_eq!(Qos::RMW_ZENOH_DEFAULT.to_keyexpr(), "::,:,:,:,,");
        assert_eq!(Qos::SENSOR_DATA.to_keyexpr(), "2::,5:,:,:,,");
        let all = Qos {
            durability: Durability::TransientLocal,
            depth: None,
            ..Qos::DEFAULT_10
        };
        assert_eq!(all.to_keyexpr(), ":1:2,:,:,:,,");
    }

    #[test]
    fn attachments_are_33_bytes_and_strict() {
        let a = Attachment {
            sequence: 7,
            timestamp_ns: 1_700_000_000_123_456_789,
            gid: gid_of("x"),
        };
        let b = a.to_bytes();
        assert_eq!(b.len(), 33);
        assert_eq!(&b[..8], &7i64.to_le_bytes());
        assert_eq!(b[16], 16);
        assert_eq!(Attachment::from_bytes(&b), Ok(a));
        assert!(Attachment::from_bytes(&b[..32]).is_err());
        let mut wrong_len = b;
        wrong_len[16] = 12;
        assert!(Attachment::from_bytes(&wrong_len).is_err());
        assert_ne!(gid_of("@ros2_lv/0/a"), gid_of("@ros2_lv/0/b"));
    }

    #[test]
    fn distros_parse() {
        assert_eq!("Jazzy".parse(), Ok(Distro::Jazzy));
        assert_eq!("humble".parse(), Ok(Distro::Humble));
        assert!("iron".parse::<Distro>().is_err());
    }
}
