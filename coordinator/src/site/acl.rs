//! The site's access-control list, as Zenoh's routing process enforces it (the
//! `access_control` block of its config). Subjects are authenticated identities: a
//! certificate common name **and** a user name, both as issued by `site init`. Everything not
//! allowed below is denied.
//!
//! | identity | may |
//! |---|---|
//! | `robot-<N>` | put `robot/N/{cmd,intent,info,fan}`; hold the token `alive/N`; subscribe to and receive `robot/N/{obs,task,traffic}`; watch the coordinator's token; query the map |
//! | `coordinator` | everything under `gapfleet/<site>/` (needed only behind a `zenohd`: when the coordinator routes, its own session is not subject to the list) |
//! | `observer-<name>` | subscribe to, watch and query anything under `gapfleet/<site>/`; never put, hold a token or answer queries |
//!
//! Keys are relative to `gapfleet/<site>/` (see `schemas::keys`). A robot cannot put on another
//! robot's keys, hold another robot's token, read another robot's observations or tasks, or
//! serve a map.

use schemas::{Channel, Keys};
use serde_json::{Value, json};

/// What a robot's agent sends.
const ROBOT_SENDS: [Channel; 4] = [Channel::Cmd, Channel::Intent, Channel::Info, Channel::Fan];
/// What a robot's agent receives.
const ROBOT_RECEIVES: [Channel; 3] = [Channel::Obs, Channel::Task, Channel::Traffic];

fn rule(id: String, messages: &[&str], flow: &str, keys: Vec<String>) -> Value {
    json!({
        "id": id,
        "messages": messages,
        "flows": [flow],
        "permission": "allow",
        "key_exprs": keys,
    })
}

/// The `access_control` block for the site of `keys` with robots 0..robots and `observers`.
pub fn access_control(keys: &Keys, robots: u32, observers: &[String]) -> Value {
    let prefix = keys.prefix();
    let mut rules = Vec::new();
    let mut subjects = Vec::new();
    let mut policies = Vec::new();
    for id in 0..robots {
        let name = format!("robot-{id}");
        let robot = |channels: &[Channel]| -> Vec<String> {
            channels.iter().map(|&c| keys.robot(id, c)).collect()
        };
        let alive = keys.alive(id);
        let coordinator = keys.coordinator();
        let map = keys.map();
        let mut ids = Vec::new();
        let mut add = |suffix: &str, messages: &[&str], flow: &str, keys: Vec<String>| {
            let id = format!("{name}-{suffix}");
            rules.push(rule(id.clone(), messages, flow, keys));
            ids.push(id);
        };
        // Its own messages, and the router telling it who subscribes to them: a client sends
        // only what someone subscribes to, and the coordinator subscribes to every robot's
        // channel with one wildcard (`robot/*/cmd`), which a rule naming robot N's key alone
        // would not let through.
        add("sends", &["put"], "ingress", robot(&ROBOT_SENDS));
        let every: Vec<String> = ROBOT_SENDS.iter().map(|&c| keys.every_robot(c)).collect();
        add("sends-to", &["declare_subscriber"], "egress", every);
        add(
            "receives",
            &["declare_subscriber"],
            "ingress",
            robot(&ROBOT_RECEIVES),
        );
        add("delivered", &["put"], "egress", robot(&ROBOT_RECEIVES));
        add("alive", &["liveliness_token"], "ingress", vec![alive]);
        add(
            "watches",
            &["declare_liveliness_subscriber", "liveliness_query"],
            "ingress",
            vec![coordinator.clone()],
        );
        add(
            "sees",
            &["liveliness_token", "reply"],
            "egress",
            vec![coordinator],
        );
        add("asks-map", &["query"], "ingress", vec![map.clone()]);
        add(
            "gets-map",
            &["reply", "declare_queryable"],
            "egress",
            vec![map],
        );
        subjects.push(subject(&name));
        policies.push(json!({ "id": name, "rules": ids, "subjects": [name] }));
    }
    let everything = vec![format!("{prefix}/**")];
    let all_messages = [
        "put",
        "delete",
        "declare_subscriber",
        "query",
        "reply",
        "declare_queryable",
        "liveliness_token",
        "liveliness_query",
        "declare_liveliness_subscriber",
    ];
    rules.push(rule(
        "coordinator-in".to_owned(),
        &all_messages,
        "ingress",
        everything.clone(),
    ));
    rules.push(rule(
        "coordinator-out".to_owned(),
        &all_messages,
        "egress",
        everything.clone(),
    ));
    subjects.push(subject("coordinator"));
    policies.push(json!({
        "id": "coordinator",
        "rules": ["coordinator-in", "coordinator-out"],
        "subjects": ["coordinator"],
    }));
    if !observers.is_empty() {
        rules.push(rule(
            "observer-in".to_owned(),
            &[
                "declare_subscriber",
                "declare_liveliness_subscriber",
                "liveliness_query",
                "query",
            ],
            "ingress",
            everything.clone(),
        ));
        rules.push(rule(
            "observer-out".to_owned(),
            &[
                "put",
                "delete",
                "reply",
                "liveliness_token",
                "declare_queryable",
            ],
            "egress",
            everything,
        ));
        let names: Vec<String> = observers.iter().map(|o| format!("observer-{o}")).collect();
        subjects.extend(names.iter().map(|n| subject(n)));
        policies.push(json!({
            "id": "observers",
            "rules": ["observer-in", "observer-out"],
            "subjects": names,
        }));
    }
    json!({
        "enabled": true,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    })
}

/// An identity as the routing process authenticates it: the certificate's common name and
/// the user name, both required.
fn subject(name: &str) -> Value {
    json!({ "id": name, "cert_common_names": [name], "usernames": [name] })
}
