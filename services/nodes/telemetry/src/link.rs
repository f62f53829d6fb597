//! The ground link the telemetry node asks the runtime for.

use crate::config::TelemetryConfig;
use crate::latest::LATEST_KEY;
use spacepose_bus::Route;
use spacepose_messages::Topic;
use spacepose_runtime::{Access, LinkSpec};

/// The session of `[zenoh]`, the `[access]` of the ground (readers and
/// operators; anyone who reaches the endpoints without it, which the
/// runtime warns about when they are not loopback), the command route from
/// zenoh to the bus and the `latest` queryable.
pub fn link_spec(config: &TelemetryConfig) -> LinkSpec {
    LinkSpec {
        zenoh: config.zenoh.zenoh_config(),
        access: config
            .access
            .as_ref()
            .map(|a| Access::Ground(a.access_control())),
        credentials: None,
        routes: vec![Route::from_zenoh(Topic::Command)],
        latest_key: Some(LATEST_KEY.to_string()),
        wait_for_link: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_bus::Direction;

    #[test]
    fn the_spec_carries_the_endpoints_the_access_and_the_command_route() {
        let mut c = TelemetryConfig::default();
        let spec = link_spec(&c);
        assert_eq!(spec.zenoh.listen, ["tcp/127.0.0.1:7447"]);
        assert!(!spec.zenoh.multicast_scouting);
        assert!(spec.access.is_none() && spec.credentials.is_none());
        assert_eq!(spec.routes.len(), 1);
        let r = &spec.routes[0];
        assert_eq!(
            (r.topic, r.direction, r.key.as_deref()),
            (Topic::Command, Direction::FromZenoh, None)
        );
        assert_eq!(spec.latest_key.as_deref(), Some("latest"));
        assert!(spec.wait_for_link.is_none());
        c.access = Some(crate::AccessConfig {
            dictionary_file: "/etc/sp/users".into(),
            operators: vec!["op".into()],
            readers: vec!["ground".into()],
            peers: Vec::new(),
        });
        match link_spec(&c).access {
            Some(Access::Ground(a)) => {
                assert_eq!(
                    (a.operators, a.readers),
                    (vec!["op".to_string()], vec!["ground".to_string()])
                );
            }
            other => panic!("{other:?}"),
        }
    }
}
