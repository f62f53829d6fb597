//! The host link the bridge node asks the runtime for.

use crate::config::{BridgeServiceConfig, RouteDirection, link_key};
use anyhow::Context;
use spacepose_bus::{Credentials, Direction, Route};
use spacepose_runtime::{Access, LinkSpec};
use std::time::Duration;

/// The session of `[zenoh]`; the link ACL of `[access]` (the runtime
/// applies it only where this host listens, and warns about endpoints
/// beyond loopback without it); the account of `credentials_file`; a route
/// per configured topic on its link key `spacepose/{suite}/link/{topic}`
/// (rates as configured, none = every sample); and the wait for the
/// consuming hosts of `wait_for_link_s`.
///
/// # Errors
/// Bad routes or suite prefix; an unreadable credentials file.
pub fn link_spec(config: &BridgeServiceConfig) -> anyhow::Result<LinkSpec> {
    let suite = config.suite()?;
    let routes = config
        .routes()?
        .into_iter()
        .map(|(topic, direction, rate)| Route {
            topic,
            direction: match direction {
                RouteDirection::ToZenoh => Direction::ToZenoh,
                RouteDirection::FromZenoh => Direction::FromZenoh,
            },
            max_rate_hz: rate,
            key: Some(link_key(&suite, topic)),
        })
        .collect();
    let credentials = config
        .credentials_file
        .as_deref()
        .map(Credentials::from_file)
        .transpose()
        .context("the link account (credentials_file)")?;
    Ok(LinkSpec {
        zenoh: config.zenoh.zenoh_config(),
        access: config
            .access
            .as_ref()
            .map(|a| Access::Link(a.access_control(), suite.clone())),
        credentials,
        routes,
        latest_key: None,
        wait_for_link: (config.wait_for_link_s > 0.0)
            .then(|| Duration::from_secs_f64(config.wait_for_link_s)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_messages::{Names, Topic};

    #[test]
    fn routes_go_on_the_link_keys_with_their_rates() {
        let config: BridgeServiceConfig = toml::from_str(
            "suite_prefix = \"orbit\"\nwait_for_link_s = 2.5\n[zenoh]\nlisten = [\"tcp/127.0.0.1:7450\"]\n\
             [access]\ndictionary_file = \"u\"\npeers = [\"host-a\"]\n\
             [[routes]]\ntopic = \"cloud\"\ndirection = \"from-zenoh\"\n\
             [[routes]]\ntopic = \"pose\"\ndirection = \"to-zenoh\"\nmax_rate_hz = 20.0\n",
        )
        .unwrap();
        let spec = link_spec(&config).unwrap();
        let names = Names::new("host-b").unwrap();
        let routes: Vec<_> = spec
            .routes
            .iter()
            .map(|r| (r.topic, r.direction, r.max_rate_hz, r.zenoh_key(&names)))
            .collect();
        assert_eq!(
            routes,
            [
                (
                    Topic::Cloud,
                    Direction::FromZenoh,
                    None,
                    "spacepose/orbit/link/cloud".to_string()
                ),
                (
                    Topic::Pose,
                    Direction::ToZenoh,
                    Some(20.0),
                    "spacepose/orbit/link/pose".to_string()
                ),
            ]
        );
        assert_eq!(spec.wait_for_link, Some(Duration::from_millis(2500)));
        assert_eq!(spec.zenoh.listen, ["tcp/127.0.0.1:7450"]);
        assert!(spec.credentials.is_none() && spec.latest_key.is_none());
        match spec.access {
            Some(Access::Link(a, suite)) => {
                assert_eq!(
                    (a.peers, suite.prefix()),
                    (vec!["host-a".to_string()], "orbit")
                );
                assert!(a.operators.is_empty() && a.readers.is_empty());
            }
            other => panic!("{other:?}"),
        }
        let mut connecting = config.clone();
        connecting.wait_for_link_s = 0.0;
        connecting.credentials_file = Some("/nonexistent/account".into());
        assert!(link_spec(&connecting).is_err());
        let dir = tempfile::tempdir().unwrap();
        let account = dir.path().join("account");
        std::fs::write(&account, "host-b:pw\n").unwrap();
        connecting.credentials_file = Some(account);
        let spec = link_spec(&connecting).unwrap();
        assert_eq!(spec.credentials.map(|c| c.user).as_deref(), Some("host-b"));
        assert_eq!(spec.wait_for_link, None);
    }
}
