//! Tests of the init service's configuration and method chain.

use super::*;

#[test]
fn defaults_are_valid_and_round_trip_through_toml() {
    let c = InitServiceConfig::default();
    c.validate().unwrap();
    let text = toml::to_string(&c).unwrap();
    let back: InitServiceConfig = toml::from_str(&text).unwrap();
    assert_eq!(back, c);
}

/// `deploy/examples/init.toml` parses, and so does its commented
/// `[template_matching]` example once uncommented.
#[test]
fn the_deploy_example_parses() {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../deploy/examples/init.toml"
    ));
    let c: InitServiceConfig = toml::from_str(text).unwrap();
    c.validate().unwrap();
    let uncommented: String = text
        .lines()
        .map(|l| match l.strip_prefix("# ") {
            Some(rest) if rest.starts_with("[template_matching") || rest.contains(" = ") => {
                rest.split('#').next().unwrap_or("").trim_end()
            }
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n");
    let c: InitServiceConfig = toml::from_str(&uncommented).unwrap();
    c.validate().unwrap();
    assert_eq!(c.template_matching.u_max, 0.3);
    assert_eq!(c.template_matching.icp.max_iterations, 40);
    assert_eq!(
        c.template_matching.far_lookup,
        TemplateMatchingConfig::default().far_lookup
    );
}

/// The file's `instance` is the instance name unless `--instance` is
/// given; the trait's validation is the config's.
#[test]
fn the_instance_key_names_the_instance() {
    let c: InitServiceConfig = toml::from_str("instance = \"init-b\"\n").unwrap();
    assert_eq!(ServiceConfig::instance(&c), Some("init-b"));
    assert_eq!(ServiceConfig::instance(&InitServiceConfig::default()), None);
    let bad: InitServiceConfig = toml::from_str("instance = \"bad name!\"\n").unwrap();
    let e = ServiceConfig::validate(&bad).unwrap_err();
    assert!(e.contains("instance"), "{e}");
    assert!(ServiceConfig::validate(&c).is_ok());
}

#[test]
fn partial_files_take_defaults_and_unknown_keys_fail() {
    let c: InitServiceConfig =
        toml::from_str("target = \"deos\"\n[state]\nretry_after_frames = 2\n").unwrap();
    assert_eq!(c.state.retry_after_frames, 2);
    assert_eq!(
        c.state.handover_frames,
        InitConfig::default().handover_frames
    );
    assert!(toml::from_str::<InitServiceConfig>("targett = \"deos\"").is_err());
    assert!(toml::from_str::<InitServiceConfig>("[state]\nretry = 1").is_err());
    // The matcher's and its ICP's sections are partial too.
    let c: InitServiceConfig = toml::from_str(
        "[template_matching]\nu_max = 0.4\n[template_matching.icp]\nmax_iterations = 30\n",
    )
    .unwrap();
    assert_eq!(c.template_matching.u_max, 0.4);
    assert_eq!(c.template_matching.icp.max_iterations, 30);
    assert_eq!(
        c.template_matching.delta_deg,
        TemplateMatchingConfig::default().delta_deg
    );
    assert!(toml::from_str::<InitServiceConfig>("[template_matching]\numax = 0.4").is_err());
}

#[test]
fn nan_zero_and_unavailable_values_fail_validation() {
    let base = InitServiceConfig::default();
    let mut tm_nan = base.template_matching.clone();
    tm_nan.f_max_m2 = f64::NAN;
    for c in [
        InitServiceConfig {
            target_scale: f64::NAN,
            ..base.clone()
        },
        InitServiceConfig {
            integration_time_s: f64::NAN,
            ..base.clone()
        },
        InitServiceConfig {
            integration_time_s: 0.0,
            ..base.clone()
        },
        InitServiceConfig {
            methods: vec![],
            ..base.clone()
        },
        InitServiceConfig {
            methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
            cnn: CnnMethodConfig {
                f_max_m2: f64::NAN,
                ..CnnMethodConfig::default()
            },
            ..base.clone()
        },
        InitServiceConfig {
            min_points: 2,
            ..base.clone()
        },
        InitServiceConfig {
            instance: Some("bad name!".into()),
            ..base.clone()
        },
        InitServiceConfig {
            template_matching: tm_nan,
            ..base.clone()
        },
    ] {
        assert!(c.validate().is_err(), "{c:?}");
    }
}

fn package(spec: &str) -> TargetPackage {
    spacepose_prepare::resolve(spec, 1.0).unwrap()
}

/// The source tree's root, from the manifest directory cargo gives the
/// test at run time.
fn root() -> PathBuf {
    let crate_dir = std::env::var("CARGO_MANIFEST_DIR")
        .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned());
    Path::new(&crate_dir).join("../../..")
}

#[test]
fn a_target_without_a_cnn_acquires_by_template_matching_alone() {
    let both = InitServiceConfig {
        target: "envisat".into(),
        methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
        ..InitServiceConfig::default()
    };
    let why = both.cnn_model_dir(&package("envisat")).unwrap_err();
    assert!(why.contains("spacepose train"), "{why}");
    let deos = both.cnn_model_dir(&package("deos")).unwrap();
    assert!(deos.ends_with("services/core/cnn/models/deos"), "{deos:?}");
    let chain = both.build_chain().expect("template matching alone");
    let tm = spacepose_messages::AcquisitionMethod::TemplateMatching;
    assert_eq!(chain.methods(), vec![tm]);

    let cnn_only = InitServiceConfig {
        methods: vec![MethodKind::Cnn],
        ..both.clone()
    };
    let e = cnn_only.build_chain().err().expect("no method left");
    assert!(e.to_string().contains("no CNN for target envisat"), "{e}");

    let deos_model = InitServiceConfig {
        cnn: CnnMethodConfig {
            model_dir: Some(root().join("services/core/cnn/models/deos")),
            ..CnnMethodConfig::default()
        },
        ..both.clone()
    };
    let why = deos_model.cnn_model_dir(&package("envisat")).unwrap_err();
    assert!(why.contains("trained for deos"), "{why}");

    let missing = InitServiceConfig {
        cnn: CnnMethodConfig {
            model_dir: Some("/nonexistent/model".into()),
            ..CnnMethodConfig::default()
        },
        ..both
    };
    let dir = missing.cnn_model_dir(&package("envisat"));
    assert_eq!(
        dir,
        Ok(PathBuf::from("/nonexistent/model")),
        "a config error"
    );
    let e = missing
        .build_chain()
        .err()
        .expect("a missing model stops init");
    assert!(e.to_string().contains("/nonexistent/model"), "{e}");
}

/// A package directory with a model in `cnn/` (as `spacepose train`
/// writes it) serves its own model.
#[test]
fn a_package_with_a_trained_model_uses_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("deos");
    std::fs::create_dir_all(dir.join("cnn")).unwrap();
    for f in ["target.toml", "mesh.obj"] {
        std::fs::copy(root().join("deploy/targets/deos").join(f), dir.join(f)).unwrap();
    }
    for f in ["model.onnx", "model.json"] {
        let from = root().join("services/core/cnn/models/deos").join(f);
        std::fs::copy(from, dir.join("cnn").join(f)).unwrap();
    }
    let config = InitServiceConfig {
        target: dir.display().to_string(),
        methods: vec![MethodKind::Cnn],
        ..InitServiceConfig::default()
    };
    let package = package(&config.target);
    assert_eq!(config.cnn_model_dir(&package), Ok(dir.join("cnn")));
    let chain = config.build_chain().unwrap();
    let cnn = spacepose_messages::AcquisitionMethod::Cnn;
    assert_eq!(chain.methods(), vec![cnn]);
}
