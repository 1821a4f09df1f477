use std::fmt;

/// Errors reported by this crate.
///
/// Collective functions agree on errors before returning: when any rank failed, every rank
/// returns [`PartitionError::OnRank`] carrying the lowest failing rank and its message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PartitionError {
    /// Arguments given on this rank are inconsistent (lengths, ranks out of range, non-finite
    /// coordinates, ...).
    InvalidInput(String),
    /// METIS rejected the graph or failed while partitioning it.
    Metis(String),
    /// A collective call failed on `rank` (the lowest failing rank); every rank receives this.
    OnRank {
        /// Lowest rank that reported a failure.
        rank: i32,
        /// That rank's error message.
        message: String,
    },
}

impl fmt::Display for PartitionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidInput(m) => write!(f, "invalid input: {m}"),
            Self::Metis(m) => write!(f, "METIS failed: {m}"),
            Self::OnRank { rank, message } => write!(f, "rank {rank}: {message}"),
        }
    }
}

impl std::error::Error for PartitionError {}

/// Shorthand for building an [`PartitionError::InvalidInput`].
pub(crate) fn invalid(msg: impl Into<String>) -> PartitionError {
    PartitionError::InvalidInput(msg.into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_the_rank() {
        let e = PartitionError::OnRank {
            rank: 2,
            message: "invalid input: x".into(),
        };
        assert_eq!(e.to_string(), "rank 2: invalid input: x");
        assert_eq!(invalid("bad").to_string(), "invalid input: bad");
    }
}
