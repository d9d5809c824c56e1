//! Key expressions. Every key lives under `gapfleet/<site>/`:
//!
//! | key | from → to | payload |
//! |---|---|---|
//! | `gapfleet/<site>/robot/<id>/obs` | coordinator → agent | [`Observation`](crate::Observation) |
//! | `gapfleet/<site>/robot/<id>/intent` | agent → fleet | [`IntentMsg`](crate::IntentMsg) |
//! | `gapfleet/<site>/robot/<id>/cmd` | agent → coordinator | [`CommandMsg`](crate::CommandMsg) |
//! | `gapfleet/<site>/robot/<id>/task` | coordinator → agent | [`TaskAssignment`](crate::TaskAssignment) |
//! | `gapfleet/<site>/robot/<id>/info` | agent → fleet | [`AgentInfo`](crate::AgentInfo) |
//! | `gapfleet/<site>/robot/<id>/fan` | agent → dashboards (opt-in) | [`FanMsg`](crate::FanMsg) |
//! | `gapfleet/<site>/robot/<id>/traffic` | coordinator → agent, dashboards | [`TrafficMsg`](crate::TrafficMsg) |
//! | `gapfleet/<site>/alive/<id>` | agent (liveliness token) | none |
//! | `gapfleet/<site>/metrics` | coordinator → fleet | [`FleetMetrics`](crate::FleetMetrics) |
//! | `gapfleet/<site>/map` | coordinator (queryable) | [`MapMsg`](crate::MapMsg) |
//!
//! `<site>` is one chunk of letters, digits, `-` and `_`; `<id>` is a robot id in decimal.

use std::fmt;

/// The root every key starts with.
pub const ROOT: &str = "gapfleet";

/// Per-robot channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Observations for the robot.
    Obs,
    /// The robot's intent.
    Intent,
    /// The robot's commands.
    Cmd,
    /// Tasks for the robot.
    Task,
    /// The agent's heartbeat.
    Info,
    /// PGP's candidate fan, when the agent shares it.
    Fan,
    /// The traffic policy's constraint on the robot.
    Traffic,
}

impl Channel {
    /// Every channel.
    pub const ALL: [Channel; 7] = [
        Channel::Obs,
        Channel::Intent,
        Channel::Cmd,
        Channel::Task,
        Channel::Info,
        Channel::Fan,
        Channel::Traffic,
    ];

    /// The last chunk of the key.
    pub fn as_str(self) -> &'static str {
        match self {
            Channel::Obs => "obs",
            Channel::Intent => "intent",
            Channel::Cmd => "cmd",
            Channel::Task => "task",
            Channel::Info => "info",
            Channel::Fan => "fan",
            Channel::Traffic => "traffic",
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// An unusable site name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("site name {0:?} must be 1-64 characters of letters, digits, '-' and '_'")]
pub struct KeyError(pub String);

/// A site's keys from its name (a command line's `--site`): the one place a site name is
/// checked.
impl std::str::FromStr for Keys {
    type Err = KeyError;

    fn from_str(site: &str) -> Result<Self, KeyError> {
        Self::new(site)
    }
}

/// Shows the site's name.
impl fmt::Display for Keys {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.site())
    }
}

/// Builds and parses the key expressions of one site.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Keys {
    prefix: String,
}

impl Keys {
    /// Keys of `site`.
    pub fn new(site: &str) -> Result<Self, KeyError> {
        let ok = !site.is_empty()
            && site.len() <= 64
            && site
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !ok {
            return Err(KeyError(site.to_owned()));
        }
        Ok(Self {
            prefix: format!("{ROOT}/{site}"),
        })
    }

    /// `gapfleet/<site>`.
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// The site's name.
    pub fn site(&self) -> &str {
        &self.prefix[ROOT.len() + 1..]
    }

    /// `gapfleet/<site>/robot/<id>/<channel>`.
    pub fn robot(&self, id: u32, channel: Channel) -> String {
        format!("{}/robot/{id}/{channel}", self.prefix)
    }

    /// `gapfleet/<site>/robot/*/<channel>`: the channel of every robot.
    pub fn every_robot(&self, channel: Channel) -> String {
        format!("{}/robot/*/{channel}", self.prefix)
    }

    /// `gapfleet/<site>/alive/<id>`: the agent's liveliness token.
    pub fn alive(&self, id: u32) -> String {
        format!("{}/alive/{id}", self.prefix)
    }

    /// `gapfleet/<site>/alive/*`.
    pub fn every_alive(&self) -> String {
        format!("{}/alive/*", self.prefix)
    }

    /// `gapfleet/<site>/coordinator`: the coordinator's liveliness token. Agents stop their
    /// robots the moment it disappears.
    pub fn coordinator(&self) -> String {
        format!("{}/coordinator", self.prefix)
    }

    /// `gapfleet/<site>/metrics`.
    pub fn metrics(&self) -> String {
        format!("{}/metrics", self.prefix)
    }

    /// `gapfleet/<site>/map`.
    pub fn map(&self) -> String {
        format!("{}/map", self.prefix)
    }

    /// The robot id and channel of a per-robot key of this site.
    pub fn parse_robot(&self, key: &str) -> Option<(u32, Channel)> {
        let rest = key.strip_prefix(&self.prefix)?.strip_prefix("/robot/")?;
        let (id, channel) = rest.split_once('/')?;
        let channel = Channel::ALL.into_iter().find(|c| c.as_str() == channel)?;
        Some((parse_id(id)?, channel))
    }

    /// The robot id of a liveliness key of this site.
    pub fn parse_alive(&self, key: &str) -> Option<u32> {
        parse_id(key.strip_prefix(&self.prefix)?.strip_prefix("/alive/")?)
    }
}

/// Decimal robot ids without sign, leading zeros or other decoration.
fn parse_id(s: &str) -> Option<u32> {
    let canonical =
        !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) && (s == "0" || !s.starts_with('0'));
    canonical.then(|| s.parse().ok()).flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip() {
        let keys = Keys::new("site-1").unwrap();
        for channel in Channel::ALL {
            let key = keys.robot(42, channel);
            assert_eq!(
                key,
                format!("gapfleet/site-1/robot/42/{}", channel.as_str())
            );
            assert_eq!(keys.parse_robot(&key), Some((42, channel)));
        }
        assert_eq!(keys.parse_alive(&keys.alive(7)), Some(7));
        assert_eq!(
            keys.every_robot(Channel::Intent),
            "gapfleet/site-1/robot/*/intent"
        );
    }

    #[test]
    fn bad_sites_and_keys_are_rejected() {
        for site in ["", "a/b", "*", "a b", "x$", &"s".repeat(65)] {
            assert!(Keys::new(site).is_err(), "{site:?}");
        }
        let keys: Keys = "site-1".parse().unwrap();
        assert_eq!(
            (keys.site(), keys.to_string().as_str()),
            ("site-1", "site-1")
        );
        let keys = Keys::new("w").unwrap();
        for key in [
            "gapfleet/w/robot/x/obs",
            "gapfleet/w/robot/01/obs",
            "gapfleet/w/robot/-1/obs",
            "gapfleet/w/robot/1/other",
            "gapfleet/v/robot/1/obs",
            "gapfleet/w/robot/99999999999/obs",
            "gapfleet/w/robot/1",
        ] {
            assert_eq!(keys.parse_robot(key), None, "{key}");
        }
        assert_eq!(keys.parse_alive("gapfleet/w/alive/"), None);
    }
}
