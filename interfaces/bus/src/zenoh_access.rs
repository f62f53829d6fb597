//! zenoh access control of the suite's ground link: who may read telemetry
//! and who may send commands (swap, reinit, mode).
//!
//! Mechanism (zenoh 1.10): **user-password authentication** of every peer
//! that connects (`transport/auth/usrpwd`, zenoh feature `auth_usrpwd`) and
//! an **ACL by username** (`access_control`, part of every zenoh build), with
//! `default_permission = deny`.
//!
//! Why usernames rather than the other ACL subjects zenoh 1.10 offers:
//! - `interfaces`: every process of a one-machine suite, and every ground
//!   tool tunnelled to it, arrives on `lo`; an interface says nothing about
//!   who is talking.
//! - `zids`: a zenoh id is chosen by the peer itself; anyone can claim one.
//! - `cert_common_names`: needs TLS links (`transport_tls`, rustls and a
//!   certificate authority to run). The right choice for a real ground
//!   link, and the ACL below is unchanged by it (swap `usernames` for
//!   `cert_common_names`); not needed to authorise peers on one host.
//!
//! usrpwd proves the user by an HMAC of its password over a random nonce
//! (the password never crosses the link), but the link itself stays
//! unencrypted TCP: over an untrusted network use TLS or a VPN as well
//! (`docs/security.md`).
//!
//! A consequence of usrpwd in zenoh 1.10: a listener with a user dictionary
//! refuses the handshake of any peer that presents no credentials, so an
//! unauthenticated reader cannot connect at all. Ground tools that only read
//! get a *reader* account instead.
//!
//! What the policy allows, on the keys of one deployment prefix, everything
//! else being denied:
//! - readers (and operators): declare subscribers and send queries on
//!   `spacepose/{p}/telemetry/**` (ingress); receive its samples, replies
//!   and queryable declarations (egress);
//! - operators: put on `spacepose/{p}/wire/command` (ingress), and see the
//!   bridge's subscriber declaration there (egress);
//! - peers (other hosts of the same suite): everything below `spacepose/{p}/**`.

use crate::error::BusError;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use spacepose_messages::{Names, Topic};
use std::path::{Path, PathBuf};

/// Every message kind zenoh's ACL knows (the `peers` role gets them all).
const ALL_MESSAGES: [&str; 9] = [
    "put",
    "delete",
    "declare_subscriber",
    "query",
    "declare_queryable",
    "reply",
    "liveliness_token",
    "declare_liveliness_subscriber",
    "liveliness_query",
];

/// Who may do what on the ground link of a suite peer that accepts
/// connections (the telemetry service, which hosts the command bridge).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccessControl {
    /// zenoh's usrpwd dictionary: one `user:password` per line. Every
    /// connecting peer must present one of these accounts.
    pub dictionary_file: PathBuf,
    /// Accounts allowed to send commands (and to read telemetry).
    pub operators: Vec<String>,
    /// Accounts allowed to read telemetry only.
    #[serde(default)]
    pub readers: Vec<String>,
    /// Accounts of other hosts of the same suite (full access below
    /// `spacepose/{prefix}/**`).
    #[serde(default)]
    pub peers: Vec<String>,
}

/// The account a process presents when it connects (a ground tool, an
/// operator console, another suite host).
#[derive(Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Credentials {
    /// User name.
    pub user: String,
    /// Password.
    pub password: String,
}

impl std::fmt::Debug for Credentials {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Credentials")
            .field("user", &self.user)
            .field("password", &"<hidden>")
            .finish()
    }
}

impl Credentials {
    /// An account.
    pub fn new(user: &str, password: &str) -> Credentials {
        Credentials {
            user: user.to_string(),
            password: password.to_string(),
        }
    }

    /// Reads the first non-empty `user:password` line of `path`.
    pub fn from_file(path: &Path) -> Result<Credentials, BusError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| BusError::Zenoh(format!("reading {}: {e}", path.display())))?;
        let line = text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty())
            .ok_or_else(|| BusError::Zenoh(format!("{} holds no account", path.display())))?;
        let (user, password) =
            parse_account(line).map_err(|e| BusError::Zenoh(format!("{}: {e}", path.display())))?;
        Ok(Credentials::new(user, password))
    }

    /// Makes `config` present this account to every peer it connects to.
    pub fn apply(&self, config: &mut zenoh::Config) -> Result<(), BusError> {
        parse_account(&format!("{}:{}", self.user, self.password)).map_err(BusError::Zenoh)?;
        set(config, "transport/auth/usrpwd/user", &json!(self.user))?;
        set(
            config,
            "transport/auth/usrpwd/password",
            &json!(self.password),
        )
    }
}

/// Splits a `user:password` line as zenoh reads its dictionary.
fn parse_account(line: &str) -> Result<(&str, &str), String> {
    let (user, password) = line
        .split_once(':')
        .ok_or_else(|| "expected `user:password`".to_string())?;
    let (user, password) = (user.trim(), password.trim());
    if user.is_empty() || password.is_empty() {
        return Err("empty user or password".to_string());
    }
    Ok((user, password))
}

fn set(config: &mut zenoh::Config, key: &str, value: &Value) -> Result<(), BusError> {
    config
        .insert_json5(key, &value.to_string())
        .map_err(|e| BusError::Zenoh(format!("{key} = {value}: {e}")))
}

impl AccessControl {
    /// Checks the accounts: at least one operator, valid user names, no
    /// account in two roles, and every account present in the dictionary.
    pub fn validate(&self) -> Result<(), BusError> {
        if self.operators.is_empty() {
            return Err(BusError::Zenoh(
                "access control: no operator account: nobody could send commands".into(),
            ));
        }
        self.check_accounts()
    }

    /// Checks the accounts of a suite link ([`Self::apply_link`]): at least
    /// one peer, valid user names, every account in the dictionary.
    pub fn validate_link(&self) -> Result<(), BusError> {
        if self.peers.is_empty() {
            return Err(BusError::Zenoh(
                "link access control: no peer account: no host could connect".into(),
            ));
        }
        self.check_accounts()
    }

    fn check_accounts(&self) -> Result<(), BusError> {
        let bad = |m: String| Err(BusError::Zenoh(format!("access control: {m}")));
        let all: Vec<&String> = self
            .operators
            .iter()
            .chain(&self.readers)
            .chain(&self.peers)
            .collect();
        for (i, user) in all.iter().enumerate() {
            if user.is_empty() || user.contains([':', ' ', '\t']) {
                return bad(format!("invalid user name {user:?}"));
            }
            if all[..i].contains(user) {
                return bad(format!("user {user:?} appears in two roles or twice"));
            }
        }
        let text = std::fs::read_to_string(&self.dictionary_file).map_err(|e| {
            BusError::Zenoh(format!(
                "access control: reading the dictionary {}: {e}",
                self.dictionary_file.display()
            ))
        })?;
        let mut known = Vec::new();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
            let (user, _) = parse_account(line).map_err(|e| {
                BusError::Zenoh(format!(
                    "access control: {}: {e}",
                    self.dictionary_file.display()
                ))
            })?;
            known.push(user);
        }
        if let Some(missing) = all.iter().find(|u| !known.contains(&u.as_str())) {
            return bad(format!(
                "user {missing:?} has no password in {}",
                self.dictionary_file.display()
            ));
        }
        Ok(())
    }

    /// The `access_control` block of zenoh's configuration for deployment
    /// `names` (see the module documentation for the policy).
    pub fn acl_json(&self, names: &Names) -> Value {
        let telemetry = names.telemetry_key("**");
        let command = names.wire_key(Topic::Command);
        let everything = names.zenoh_key("**");
        let readers: Vec<&String> = self.operators.iter().chain(&self.readers).collect();
        let rule = |id: &str, flow: &str, messages: &[&str], key: &str| {
            json!({
                "id": id, "permission": "allow", "flows": [flow],
                "messages": messages, "key_exprs": [key],
            })
        };
        let mut subjects = vec![
            json!({ "id": "readers", "usernames": readers }),
            json!({ "id": "operators", "usernames": self.operators }),
        ];
        let mut policies = vec![
            json!({ "id": "read-telemetry", "subjects": ["readers"],
                    "rules": ["telemetry-in", "telemetry-out"] }),
            json!({ "id": "send-commands", "subjects": ["operators"],
                    "rules": ["command-in", "command-out"] }),
        ];
        if !self.peers.is_empty() {
            subjects.push(json!({ "id": "peers", "usernames": self.peers }));
            policies.push(json!({ "id": "suite-peers", "subjects": ["peers"],
                                  "rules": ["peer-in", "peer-out"] }));
        }
        json!({
            "enabled": true,
            "default_permission": "deny",
            "rules": [
                rule("telemetry-in", "ingress", &["declare_subscriber", "query"], &telemetry),
                rule("telemetry-out", "egress",
                     &["put", "delete", "reply", "declare_queryable"], &telemetry),
                rule("command-in", "ingress", &["put"], &command),
                rule("command-out", "egress", &["declare_subscriber"], &command),
                rule("peer-in", "ingress", &ALL_MESSAGES, &everything),
                rule("peer-out", "egress", &ALL_MESSAGES, &everything),
            ],
            "subjects": subjects,
            "policies": policies,
        })
    }

    /// The `access_control` block of a suite link (the zenoh session of a
    /// host's bridge in a partitioned deployment whose keys are below
    /// `names`): only the `peers` accounts, everything below
    /// `spacepose/{p}/**`, default deny. Operators and readers talk to the
    /// telemetry service, not to the link.
    pub fn link_acl_json(&self, names: &Names) -> Value {
        let everything = names.zenoh_key("**");
        json!({
            "enabled": true,
            "default_permission": "deny",
            "rules": [
                { "id": "peer-in", "permission": "allow", "flows": ["ingress"],
                  "messages": ALL_MESSAGES, "key_exprs": [everything] },
                { "id": "peer-out", "permission": "allow", "flows": ["egress"],
                  "messages": ALL_MESSAGES, "key_exprs": [everything] },
            ],
            "subjects": [{ "id": "peers", "usernames": self.peers }],
            "policies": [{ "id": "suite-peers", "subjects": ["peers"],
                           "rules": ["peer-in", "peer-out"] }],
        })
    }

    /// Makes `config` (a host's link session) require a `peers` account of
    /// the dictionary from every connecting host and enforce
    /// [`Self::link_acl_json`].
    ///
    /// zenoh's usrpwd authenticates the side that connects to the side that
    /// accepts, not the other way round: the accepting session knows the
    /// connecting host's user name, the connecting one does not know the
    /// acceptor's. So only sessions that listen get this ACL (a connecting
    /// session with it would deny its own links); hosts that only connect
    /// listen nowhere and trust the endpoint they were told to connect to.
    pub fn apply_link(&self, names: &Names, config: &mut zenoh::Config) -> Result<(), BusError> {
        self.validate_link()?;
        self.set_dictionary(config)?;
        set(config, "access_control", &self.link_acl_json(names))
    }

    fn set_dictionary(&self, config: &mut zenoh::Config) -> Result<(), BusError> {
        let dictionary = self.dictionary_file.to_str().ok_or_else(|| {
            BusError::Zenoh(format!(
                "access control: dictionary path {} is not UTF-8",
                self.dictionary_file.display()
            ))
        })?;
        set(
            config,
            "transport/auth/usrpwd/dictionary_file",
            &json!(dictionary),
        )
    }

    /// Makes `config` require an account of the dictionary from every
    /// connecting peer and enforce the policy of deployment `names`.
    pub fn apply(&self, names: &Names, config: &mut zenoh::Config) -> Result<(), BusError> {
        self.validate()?;
        self.set_dictionary(config)?;
        set(config, "access_control", &self.acl_json(names))
    }
}

#[cfg(test)]
#[path = "zenoh_access_tests.rs"]
mod tests;
