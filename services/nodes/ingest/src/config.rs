//! The service's configuration file: the crop stage's [`IngestConfig`] as
//! it is (keys in `deploy/examples/ingest.toml`).

use serde::Deserialize;
use spacepose_ingest::IngestConfig;
use spacepose_runtime::ServiceConfig;

/// `spacepose-ingest --config FILE`: an [`IngestConfig`].
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(transparent)]
pub struct IngestServiceConfig(pub IngestConfig);

impl ServiceConfig for IngestServiceConfig {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())
    }
}
