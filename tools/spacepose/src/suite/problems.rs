//! The problems of a deployment descriptor, all reported at once (by
//! validation into a plan and by the split of a partitioned descriptor).

/// Every problem of a descriptor, one line each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problems(pub Vec<String>);

impl std::fmt::Display for Problems {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the deployment descriptor has {} problem(s):",
            self.0.len()
        )?;
        for p in &self.0 {
            write!(f, "\n  - {p}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Problems {}
