//! The suite sub-commands: command-line arguments to the modules' `run`.

use super::demo::DemoOptions;
use super::up::Overrides;
use crate::cli::{
    DemoArgs, GroundArgs, PrefixArgs, ReplayArgs, SwapArgs, UpArgs, ZenohOverrideArgs,
};
use crate::ground::GroundOptions;
use anyhow::{Result, bail};
use std::time::Duration;

fn overrides(a: &ZenohOverrideArgs) -> Overrides {
    Overrides {
        prefix: a.prefix.clone(),
        listen: (!a.listen.is_empty()).then(|| a.listen.clone()),
        connect: (!a.connect.is_empty()).then(|| a.connect.clone()),
        host: None,
        record: None,
        view: None,
    }
}

/// The recording of `--record`, checked ([`super::record::record_path`]).
fn record(arg: Option<&std::path::Path>) -> Result<Option<std::path::PathBuf>> {
    arg.map(super::record::record_path).transpose()
}

/// The live view of `--view`, checked ([`super::record::view_addr`]).
fn view(arg: Option<std::net::SocketAddr>) -> Result<Option<std::net::SocketAddr>> {
    arg.map(super::record::view_addr).transpose()
}

fn up_overrides(a: &UpArgs) -> Result<Overrides> {
    Ok(Overrides {
        host: a.host.clone(),
        record: record(a.record.as_deref())?,
        view: view(a.view)?,
        ..overrides(&a.overrides)
    })
}

fn announce_view(addr: Option<std::net::SocketAddr>) {
    if let Some(addr) = addr {
        println!("live view: open ws://{addr} in Foxglove (Open connection > Foxglove WebSocket)");
    }
}

fn seconds(name: &str, s: f64) -> Result<Duration> {
    if !(s.is_finite() && s >= 0.0) {
        bail!("{name} must be a non-negative number of seconds, got {s}");
    }
    Ok(Duration::from_secs_f64(s))
}

/// `spacepose up`.
pub fn up(a: &UpArgs) -> Result<()> {
    let overrides = up_overrides(a)?;
    announce_view(overrides.view);
    super::up::run(&a.deploy, &overrides, &mut std::io::stdout())
}

/// `spacepose supervise` (started by `up`).
pub fn supervise(a: &UpArgs) -> Result<()> {
    super::up::supervise(&a.deploy, &up_overrides(a)?)
}

/// `spacepose swap`.
pub fn swap(a: &SwapArgs) -> Result<()> {
    let kind: spacepose_messages::ServiceKind = toml::Value::String(a.kind.clone())
        .try_into()
        .map_err(|_| anyhow::anyhow!("unknown service kind {:?}", a.kind))?;
    let req = super::swap::SwapRequest {
        kind,
        mode: a.mode.clone(),
        binary: a.binary.clone(),
    };
    super::up::request_swap(
        a.prefix.as_deref(),
        &req,
        seconds("--timeout-s", a.timeout_s)?,
        &mut std::io::stdout(),
    )
}

/// `spacepose status`.
pub fn status(a: &PrefixArgs) -> Result<()> {
    super::status::run(a.prefix.as_deref(), &mut std::io::stdout())
}

/// `spacepose down`.
pub fn down(a: &PrefixArgs) -> Result<()> {
    super::down::run(a.prefix.as_deref(), &mut std::io::stdout())
}

/// `spacepose demo`.
pub fn demo(a: &DemoArgs) -> Result<()> {
    let opts = DemoOptions {
        deploy: a.deploy.clone(),
        frames: a.frames,
        seed: a.seed,
        target: a
            .target
            .as_deref()
            .map(|t| super::demo::target::TargetOverride::resolve(t, a.scale))
            .transpose()?,
        warmup: a.warmup,
        json: a.json.clone(),
        overrides: Overrides {
            record: record(a.record.as_deref())?,
            view: view(a.view)?,
            ..overrides(&a.overrides)
        },
        linger: seconds("--linger-s", a.linger_s)?,
        chaos: a
            .chaos
            .iter()
            .map(|c| super::demo::chaos::ChaosSpec::parse(c))
            .collect::<Result<_>>()?,
        swap: a
            .swap
            .as_deref()
            .map(super::demo::chaos::SwapSpec::parse)
            .transpose()?,
    };
    announce_view(opts.overrides.view);
    super::demo::run(&opts, &mut std::io::stdout())?;
    Ok(())
}

/// `spacepose replay`.
pub fn replay(a: &ReplayArgs) -> Result<()> {
    if let Some(r) = a.rate_hz.filter(|r| !(r.is_finite() && *r >= 0.0)) {
        bail!("--rate-hz must be a finite number >= 0, got {r}");
    }
    let opts = super::replay::ReplayOptions {
        input: a.input.clone(),
        deploy: a.deploy.clone(),
        rate_hz: a.rate_hz,
        json: a.json.clone(),
        overrides: Overrides {
            record: record(a.record.as_deref())?,
            ..overrides(&a.overrides)
        },
        linger: seconds("--linger-s", a.linger_s)?,
    };
    super::replay::run(&opts, &mut std::io::stdout())?;
    Ok(())
}

/// `spacepose ground`.
pub fn ground(a: &GroundArgs) -> Result<()> {
    let connect = if a.connect.is_empty() && a.listen.is_empty() {
        vec![super::descriptor::DEFAULT_LISTEN.to_string()]
    } else {
        a.connect.clone()
    };
    let opts = GroundOptions {
        connect,
        listen: a.listen.clone(),
        prefix: a.prefix.clone(),
        record: a.record.clone(),
        duration: a.duration.map(|d| seconds("--duration", d)).transpose()?,
        count: a.count,
        refresh: (a.refresh_s > 0.0)
            .then(|| seconds("--refresh-s", a.refresh_s))
            .transpose()?,
    };
    crate::ground::run(&opts, &mut std::io::stdout())?;
    Ok(())
}
