//! Tests of the ground-link access control: credentials, accounts, the ACL
//! and the zenoh configuration it produces.

use super::*;

fn dictionary(text: &str) -> tempfile::NamedTempFile {
    let f = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(f.path(), text).unwrap();
    f
}

fn access(path: &Path) -> AccessControl {
    AccessControl {
        dictionary_file: path.to_path_buf(),
        operators: vec!["op".into()],
        readers: vec!["ground".into()],
        peers: Vec::new(),
    }
}

#[test]
fn the_policy_is_accepted_by_zenoh_and_denies_by_default() {
    let d = dictionary("op:secret\nground : ro-pass\n\n");
    let names = Names::new("acl").unwrap();
    let mut c = ZenohConfigForTest::config();
    access(d.path()).apply(&names, &mut c).unwrap();
    let acl = access(d.path()).acl_json(&names);
    assert_eq!(acl["default_permission"], "deny");
    assert_eq!(
        acl["rules"][2]["key_exprs"][0],
        "spacepose/acl/wire/command"
    );
    assert_eq!(acl["subjects"][0]["usernames"], json!(["op", "ground"]));
    assert_eq!(acl["subjects"][1]["usernames"], json!(["op"]));
    // zenoh parsed it back into its own types.
    let back = c.get_json("access_control/default_permission").unwrap();
    assert_eq!(back, "\"deny\"");
    let dict = c.get_json("transport/auth/usrpwd/dictionary_file").unwrap();
    assert!(dict.contains(d.path().to_str().unwrap()));
}

#[test]
fn bad_accounts_are_refused() {
    let d = dictionary("op:secret\n");
    let names = Names::new("acl").unwrap();
    let mut c = ZenohConfigForTest::config();
    // "ground" has no password in the dictionary.
    let e = access(d.path()).apply(&names, &mut c).unwrap_err();
    assert!(e.to_string().contains("ground"), "{e}");
    let mut a = access(d.path());
    a.readers.clear();
    a.validate().unwrap();
    a.operators.clear();
    assert!(a.validate().is_err());
    let mut a = access(d.path());
    a.readers = vec!["op".into()];
    assert!(a.validate().unwrap_err().to_string().contains("two roles"));
    let bad = dictionary("nocolon\n");
    let mut a = access(bad.path());
    a.readers.clear();
    assert!(a.validate().is_err());
    assert!(toml_like_parse(r#"{"dictionary_file":"x","operators":[],"writers":[]}"#).is_err());
}

#[test]
fn a_suite_link_admits_only_peers_and_needs_no_operator() {
    let d = dictionary("host-a:pa\nhost-b:pb\n");
    let names = Names::new("orbit").unwrap();
    let link = AccessControl {
        dictionary_file: d.path().to_path_buf(),
        operators: Vec::new(),
        readers: Vec::new(),
        peers: vec!["host-a".into(), "host-b".into()],
    };
    let mut c = ZenohConfigForTest::config();
    link.apply_link(&names, &mut c).unwrap();
    let acl = link.link_acl_json(&names);
    assert_eq!(acl["default_permission"], "deny");
    assert_eq!(acl["rules"][0]["key_exprs"][0], "spacepose/orbit/**");
    assert_eq!(acl["subjects"][0]["usernames"], json!(["host-a", "host-b"]));
    assert_eq!(
        c.get_json("access_control/default_permission").unwrap(),
        "\"deny\""
    );
    // The ground-link policy still insists on an operator.
    assert!(link.validate().is_err());
    let mut none = link.clone();
    none.peers.clear();
    assert!(none.apply_link(&names, &mut c).is_err());
    let mut unknown = link;
    unknown.peers.push("host-x".into());
    assert!(
        unknown
            .validate_link()
            .unwrap_err()
            .to_string()
            .contains("host-x")
    );
}

#[test]
fn credentials_come_from_a_file_and_hide_the_password() {
    let d = dictionary("\n  op : secret \n");
    let c = Credentials::from_file(d.path()).unwrap();
    assert_eq!(c, Credentials::new("op", "secret"));
    assert!(!format!("{c:?}").contains("secret"));
    let mut z = ZenohConfigForTest::config();
    c.apply(&mut z).unwrap();
    assert_eq!(z.get_json("transport/auth/usrpwd/user").unwrap(), "\"op\"");
    assert!(Credentials::new("", "x").apply(&mut z).is_err());
    assert!(Credentials::from_file(dictionary("\n").path()).is_err());
}

fn toml_like_parse(s: &str) -> Result<AccessControl, serde_json::Error> {
    serde_json::from_str(s)
}

struct ZenohConfigForTest;
impl ZenohConfigForTest {
    fn config() -> zenoh::Config {
        crate::ZenohConfig::loopback(7447).to_zenoh().unwrap()
    }
}
