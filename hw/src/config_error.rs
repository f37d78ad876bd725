//! [`ConfigError`]: a device configuration value that is out of range, named by its key.

/// A configuration value that cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct ConfigError {
    /// The key (as in the rig file's section).
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl ConfigError {
    /// An error for `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// Checks that `address` looks like `host:port`.
#[cfg(feature = "comau")]
pub(crate) fn check_address(key: &str, address: &str) -> Result<(), ConfigError> {
    let ok = address
        .rsplit_once(':')
        .is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok());
    if ok {
        Ok(())
    } else {
        Err(ConfigError::new(
            key,
            format!("`{address}` is not host:port"),
        ))
    }
}

/// Checks that `seconds` is a usable timeout.
#[cfg(feature = "comau")]
pub(crate) fn check_timeout(key: &str, seconds: f64) -> Result<(), ConfigError> {
    if seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0 {
        Ok(())
    } else {
        Err(ConfigError::new(
            key,
            format!("must be a positive number of seconds, got {seconds}"),
        ))
    }
}
