//! A secured site: `gapfleet site init` writes a site's certificate authority, one identity per
//! process (a certificate signed by that authority and a user name with a password), and the
//! Zenoh configs that use them: mutual TLS on every link, user/password authentication on top,
//! and an access-control list, enforced by the routing process, that lets each identity do
//! exactly its part (see [`acl`]).
//!
//! ```text
//! <dir>/ca.pem  ca-key.pem  credentials.txt  site.json
//!       coordinator/{cert.pem, key.pem, zenoh.json5, behind-router.json5}
//!       router/{cert.pem, key.pem, zenohd.json5}
//!       robot-<id>/{cert.pem, key.pem, zenoh.json5}
//!       observer-<name>/{cert.pem, key.pem, zenoh.json5}
//! ```
//!
//! Two topologies use the same files: the coordinator routes (`coordinator/zenoh.json5`, the
//! access-control list in it), or a `zenohd` router does (`router/zenohd.json5`, with the list)
//! and the coordinator is one of its clients (`coordinator/behind-router.json5`). Configs name
//! the other files by absolute path. Keys, passwords and configs are written readable by the
//! owner only; `ca-key.pem` is needed only to issue more identities and belongs offline.

pub mod acl;
mod certs;

use fleet_net::Role;
use schemas::Keys;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// What a site is made of.
#[derive(Debug, Clone)]
pub struct SiteSpec {
    /// The site's keys (its name is the second chunk of every key).
    pub keys: Keys,
    /// Robots 0..robots get an identity each.
    pub robots: u32,
    /// Read-only observers (dashboards, the Python client), by name.
    pub observers: Vec<String>,
    /// Where agents, observers and a coordinator behind a router connect, e.g.
    /// `tls/127.0.0.1:7447`.
    pub endpoint: String,
    /// Where the routing process listens (default: `endpoint`), e.g. `tls/0.0.0.0:7447`.
    pub listen: Option<String>,
    /// DNS names and IP addresses the routing process's certificate is valid for; clients
    /// check the endpoint's host against them.
    pub hosts: Vec<String>,
    /// Days the certificates are valid from now.
    pub valid_days: u32,
}

impl SiteSpec {
    /// A loopback site: `robots` robots, observers `dashboard` and `python`, routed at
    /// `tls/127.0.0.1:<port>`.
    pub fn loopback(keys: &Keys, robots: u32, port: u16) -> Self {
        Self {
            keys: keys.clone(),
            robots,
            observers: vec!["dashboard".to_owned(), "python".to_owned()],
            endpoint: format!("tls/127.0.0.1:{port}"),
            listen: None,
            hosts: vec!["127.0.0.1".to_owned(), "localhost".to_owned()],
            valid_days: 825,
        }
    }

    fn check(&self) -> Result<(), SiteError> {
        if self.robots == 0 || self.robots as usize > schemas::codec::MAX_ROBOTS {
            return Err(SiteError::Spec(format!(
                "robots must be in 1..={}, not {}",
                schemas::codec::MAX_ROBOTS,
                self.robots
            )));
        }
        for name in &self.observers {
            let ok = !name.is_empty()
                && name.len() <= 32
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
            if !ok {
                return Err(SiteError::Spec(format!(
                    "observer name {name:?} must be 1-32 letters, digits, '-' or '_'"
                )));
            }
        }
        let mut seen = std::collections::BTreeSet::new();
        if let Some(twice) = self.observers.iter().find(|n| !seen.insert(*n)) {
            return Err(SiteError::Spec(format!("observer {twice:?} named twice")));
        }
        for endpoint in std::iter::once(&self.endpoint).chain(&self.listen) {
            let ok = endpoint
                .strip_prefix("tls/")
                .and_then(|a| a.rsplit_once(':'))
                .is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok());
            if !ok {
                return Err(SiteError::Spec(format!(
                    "endpoint {endpoint:?} must be tls/<host>:<port>"
                )));
            }
        }
        if self.hosts.is_empty() {
            return Err(SiteError::Spec(
                "the router's certificate needs at least one host name or address".to_owned(),
            ));
        }
        if self.valid_days == 0 {
            return Err(SiteError::Spec("valid days must be at least 1".to_owned()));
        }
        Ok(())
    }
}

/// Who holds an identity.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Identity {
    /// The coordinator (routing, or a client of a router).
    Coordinator,
    /// A `zenohd` router.
    Router,
    /// Robot `id`'s agent.
    Robot(u32),
    /// A read-only observer.
    Observer(String),
}

impl Identity {
    /// Its name: the certificate's common name, the user name, the folder and the
    /// access-control subject.
    pub fn name(&self) -> String {
        match self {
            Identity::Coordinator => "coordinator".to_owned(),
            Identity::Router => "router".to_owned(),
            Identity::Robot(id) => format!("robot-{id}"),
            Identity::Observer(name) => format!("observer-{name}"),
        }
    }

    /// Whether the certificate names the routing hosts (it accepts connections).
    fn listens(&self) -> bool {
        matches!(self, Identity::Coordinator | Identity::Router)
    }
}

/// A site's files, as written by [`init`].
#[derive(Debug, Clone)]
pub struct SitePaths {
    /// The site's folder (absolute).
    pub dir: PathBuf,
}

impl SitePaths {
    /// The certificate authority's certificate.
    pub fn ca(&self) -> PathBuf {
        self.dir.join("ca.pem")
    }

    /// `identity`'s folder.
    pub fn folder(&self, identity: &Identity) -> PathBuf {
        self.dir.join(identity.name())
    }

    /// The coordinator's config when it routes (with the access-control list).
    pub fn coordinator_config(&self) -> PathBuf {
        self.folder(&Identity::Coordinator).join("zenoh.json5")
    }

    /// The coordinator's config as a client of a `zenohd` router.
    pub fn coordinator_behind_router_config(&self) -> PathBuf {
        self.folder(&Identity::Coordinator)
            .join("behind-router.json5")
    }

    /// The `zenohd` router's config (with the access-control list).
    pub fn router_config(&self) -> PathBuf {
        self.folder(&Identity::Router).join("zenohd.json5")
    }

    /// Robot `id`'s agent config.
    pub fn robot_config(&self, id: u32) -> PathBuf {
        self.folder(&Identity::Robot(id)).join("zenoh.json5")
    }

    /// Observer `name`'s config.
    pub fn observer_config(&self, name: &str) -> PathBuf {
        self.folder(&Identity::Observer(name.to_owned()))
            .join("zenoh.json5")
    }
}

/// Why a site could not be written.
#[derive(Debug, thiserror::Error)]
pub enum SiteError {
    /// The description is unusable.
    #[error("site: {0}")]
    Spec(String),
    /// The folder already holds a site (or other files).
    #[error(
        "site: {0} is not empty; a new authority would lock out every identity issued from the old one (remove it first)"
    )]
    NotEmpty(PathBuf),
    /// A certificate could not be made.
    #[error("site: certificate: {0}")]
    Certificate(#[from] rcgen::Error),
    /// A file could not be written.
    #[error("site: {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SiteError + '_ {
    move |source| SiteError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes `content` to `path`; secrets are readable by the owner only.
fn write(path: &Path, content: &str, secret: bool) -> Result<(), SiteError> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(if secret { 0o600 } else { 0o644 })
        .open(path)
        .map_err(io(path))?;
    file.write_all(content.as_bytes()).map_err(io(path))
}

/// A random password: 32 letters and digits from the operating system's entropy (through
/// rand's thread generator, a CSPRNG seeded by the OS).
fn password() -> String {
    use rand::Rng;
    use rand::distr::Alphanumeric;
    rand::rng()
        .sample_iter(&Alphanumeric)
        .take(32)
        .map(char::from)
        .collect()
}

/// Writes a new site into `dir` (created if missing; it must be empty).
pub fn init(dir: &Path, spec: &SiteSpec) -> Result<SitePaths, SiteError> {
    spec.check()?;
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    if std::fs::read_dir(dir).map_err(io(dir))?.next().is_some() {
        return Err(SiteError::NotEmpty(dir.to_path_buf()));
    }
    let dir = dir.canonicalize().map_err(io(dir))?;
    let paths = SitePaths { dir: dir.clone() };
    let ca = certs::Authority::new(spec.keys.site(), spec.valid_days)?;
    write(&paths.ca(), &ca.cert_pem(), false)?;
    write(&dir.join("ca-key.pem"), &ca.key_pem(), true)?;

    let mut identities = vec![Identity::Coordinator, Identity::Router];
    identities.extend((0..spec.robots).map(Identity::Robot));
    identities.extend(spec.observers.iter().cloned().map(Identity::Observer));
    let mut dictionary = String::new();
    let mut credentials = Vec::with_capacity(identities.len());
    for identity in &identities {
        let name = identity.name();
        let folder = paths.folder(identity);
        std::fs::create_dir(&folder).map_err(io(&folder))?;
        let hosts = if identity.listens() {
            spec.hosts.clone()
        } else {
            Vec::new()
        };
        let leaf = ca.issue(&name, hosts, spec.valid_days)?;
        write(&folder.join("cert.pem"), &leaf.cert_pem, false)?;
        write(&folder.join("key.pem"), &leaf.key_pem, true)?;
        let password = password();
        dictionary.push_str(&format!("{name}:{password}\n"));
        credentials.push((identity.clone(), password));
    }
    let dictionary_path = dir.join("credentials.txt");
    write(&dictionary_path, &dictionary, true)?;

    let keys = spec.keys.clone();
    let access = acl::access_control(&keys, spec.robots, &spec.observers);
    let listen = spec.listen.as_deref().unwrap_or(&spec.endpoint);
    for (identity, password) in &credentials {
        let tls = Tls {
            ca: paths.ca(),
            folder: paths.folder(identity),
        };
        let user = Credentials {
            user: identity.name(),
            password: password.clone(),
        };
        match identity {
            Identity::Coordinator => {
                let routing = routing_config(&tls, &user, listen, &dictionary_path, &access);
                write(&paths.coordinator_config(), &pretty(&routing), true)?;
                let client = client_config(&tls, &user, &spec.endpoint);
                write(
                    &paths.coordinator_behind_router_config(),
                    &pretty(&client),
                    true,
                )?;
            }
            Identity::Router => {
                let routing = routing_config(&tls, &user, listen, &dictionary_path, &access);
                write(&paths.router_config(), &pretty(&routing), true)?;
            }
            Identity::Robot(_) | Identity::Observer(_) => {
                let client = client_config(&tls, &user, &spec.endpoint);
                write(
                    &paths.folder(identity).join("zenoh.json5"),
                    &pretty(&client),
                    true,
                )?;
            }
        }
    }
    let description = json!({
        "site": spec.keys.site(),
        "robots": spec.robots,
        "observers": spec.observers,
        "endpoint": spec.endpoint,
        "listen": listen,
        "hosts": spec.hosts,
        "valid_days": spec.valid_days,
    });
    write(&dir.join("site.json"), &pretty(&description), false)?;
    Ok(paths)
}

/// A site written into a fresh temporary folder for a loopback run (the demo's `--secure`,
/// benchmarks, tests), routed at a free port on 127.0.0.1; the folder goes when this does.
#[derive(Debug)]
pub struct TemporarySite {
    /// Its files.
    pub paths: SitePaths,
}

impl TemporarySite {
    /// A loopback site of `keys` with robots 0..robots and observers `dashboard` and `python`.
    pub fn new(keys: &Keys, robots: u32) -> Result<Self, SiteError> {
        let site = keys.site();
        static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("gapfleet-site-{site}-{}-{n}", std::process::id()));
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map_err(io(&dir))?
            .port();
        // Leftovers of a crashed earlier process with this pid would make init refuse.
        let _ = std::fs::remove_dir_all(&dir);
        let paths = init(&dir, &SiteSpec::loopback(keys, robots, port))?;
        Ok(Self { paths })
    }
}

impl Drop for TemporarySite {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.paths.dir);
    }
}

fn pretty(value: &Value) -> String {
    // JSON is JSON5; serde_json's pretty printer cannot fail on a `Value`.
    serde_json::to_string_pretty(value).unwrap_or_default() + "\n"
}

/// An identity's TLS files.
struct Tls {
    ca: PathBuf,
    folder: PathBuf,
}

/// An identity's user name and password.
struct Credentials {
    user: String,
    password: String,
}

/// What every gapfleet session sets: no multicast scouting, the fleet's publications batched
/// (see [`fleet_net::FLEET_QOS`]).
fn common(mode: Role) -> Value {
    let qos: Value =
        serde_json::from_str(fleet_net::FLEET_QOS).expect("FLEET_QOS is a JSON constant");
    json!({
        "mode": mode.as_str(),
        "scouting": { "multicast": { "enabled": false } },
        "qos": { "publication": qos },
    })
}

fn path(p: &Path) -> String {
    p.display().to_string()
}

/// Mutual TLS with `tls`'s certificate, a lease of [`fleet_net::LEASE_MS`], a drop
/// wait of [`fleet_net::DROP_WAIT_US`], [`fleet_net::DATA_QUEUE_BATCHES`]
/// batches for data, and
/// `user`'s login; a routing process (`dictionary` given) also listens with the certificate
/// and checks logins against the dictionary.
fn transport(tls: &Tls, user: &Credentials, dictionary: Option<&Path>) -> Value {
    let key = path(&tls.folder.join("key.pem"));
    let cert = path(&tls.folder.join("cert.pem"));
    let mut link_tls = json!({
        "root_ca_certificate": path(&tls.ca),
        "connect_private_key": key,
        "connect_certificate": cert,
        "enable_mtls": true,
        "verify_name_on_connect": true,
    });
    let mut usrpwd = json!({ "user": user.user, "password": user.password });
    if let Some(dictionary) = dictionary {
        link_tls["listen_private_key"] = key.into();
        link_tls["listen_certificate"] = cert.into();
        usrpwd["dictionary_file"] = path(dictionary).into();
    }
    json!({
        "link": {
            "protocols": ["tls"],
            "tx": {
                "lease": fleet_net::LEASE_MS,
                "queue": {
                    "size": { "data": fleet_net::DATA_QUEUE_BATCHES },
                    "congestion_control": { "drop": {
                        "wait_before_drop": fleet_net::DROP_WAIT_US,
                    } },
                },
            },
            "tls": link_tls,
        },
        "auth": { "usrpwd": usrpwd },
    })
}

/// The routing process (coordinator or zenohd): listens with its certificate, requires a
/// client certificate (mutual TLS) and a user in the dictionary, and enforces `access`.
fn routing_config(
    tls: &Tls,
    user: &Credentials,
    listen: &str,
    dictionary: &Path,
    access: &Value,
) -> Value {
    let mut config = common(Role::Router);
    config["listen"] = json!({ "endpoints": [listen] });
    config["transport"] = transport(tls, user, Some(dictionary));
    config["access_control"] = access.clone();
    config
}

/// A client of the routing process: connects over TLS with its certificate and checks the
/// router's name against the endpoint's host; waits for the router however long it takes.
fn client_config(tls: &Tls, user: &Credentials, endpoint: &str) -> Value {
    let mut config = common(Role::Client);
    config["connect"] = json!({ "endpoints": [endpoint], "timeout_ms": -1 });
    config["transport"] = transport(tls, user, None);
    config
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Keys {
        Keys::new("unit").expect("a valid site name")
    }

    /// A folder named `name` (not yet there) in a temporary folder removed when dropped.
    fn temp_dir(name: &str) -> (tempfile::TempDir, PathBuf) {
        let tmp = tempfile::tempdir().expect("a temporary folder");
        let dir = tmp.path().join(name);
        (tmp, dir)
    }

    /// Every file is written, secrets owner-only, every config parses as a Zenoh config with
    /// the fleet's transport settings, and a second init into the same folder is refused.
    #[test]
    fn init_writes_a_site_zenoh_accepts() {
        use std::os::unix::fs::PermissionsExt;
        let (_tmp, dir) = temp_dir("init");
        let paths = init(&dir, &SiteSpec::loopback(&unit(), 3, 7447)).expect("a site");
        for config in [
            paths.coordinator_config(),
            paths.coordinator_behind_router_config(),
            paths.router_config(),
            paths.robot_config(0),
            paths.robot_config(2),
            paths.observer_config("python"),
        ] {
            let zenoh = zenoh::Config::from_file(&config)
                .unwrap_or_else(|e| panic!("{}: {e}", config.display()));
            fleet_net::check_fleet_settings(&zenoh)
                .unwrap_or_else(|e| panic!("{}: {e}", config.display()));
            let mode = std::fs::metadata(&config)
                .expect("written")
                .permissions()
                .mode();
            assert_eq!(mode & 0o777, 0o600, "{} holds a password", config.display());
        }
        let key = paths.folder(&Identity::Robot(1)).join("key.pem");
        let mode = std::fs::metadata(&key)
            .expect("written")
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o600);
        let dictionary = std::fs::read_to_string(dir.join("credentials.txt")).expect("written");
        assert_eq!(dictionary.lines().count(), 2 + 3 + 2);
        assert!(
            dictionary
                .lines()
                .all(|l| l.split_once(':').is_some_and(|(_, p)| p.len() == 32))
        );
        assert!(matches!(
            init(&dir, &SiteSpec::loopback(&unit(), 3, 7447)),
            Err(SiteError::NotEmpty(_))
        ));
    }

    #[test]
    fn bad_specs_are_refused_with_the_reason() {
        let (_tmp, dir) = temp_dir("bad");
        let mut spec = SiteSpec::loopback(&unit(), 3, 7447);
        spec.endpoint = "tcp/127.0.0.1:7447".to_owned();
        let err = init(&dir, &spec)
            .expect_err("tcp is not secured")
            .to_string();
        assert!(err.contains("tls/<host>:<port>"), "{err}");
        let mut spec = SiteSpec::loopback(&unit(), 0, 7447);
        assert!(
            init(&dir, &spec)
                .expect_err("no robots")
                .to_string()
                .contains("robots")
        );
        spec.robots = 2;
        spec.observers = vec!["a b".to_owned()];
        assert!(
            init(&dir, &spec)
                .expect_err("a space")
                .to_string()
                .contains("observer")
        );
        spec.observers = vec!["x".to_owned(), "x".to_owned()];
        assert!(
            init(&dir, &spec)
                .expect_err("twice")
                .to_string()
                .contains("twice")
        );
        // A bad site name never gets this far: `--site` is parsed into `Keys`.
        assert!("no/slash".parse::<Keys>().is_err());
        let spec = SiteSpec::loopback(&unit(), 0, 7447);
        assert!(init(&dir, &spec).is_err());
        assert!(!dir.exists(), "nothing is written for a refused spec");
    }
}
