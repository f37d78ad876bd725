//! [`Contact`]: a robot link touching something, as the twin reports it.

use nbv_core::rig::TruthLabel;
use std::fmt;

/// What a robot link touches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Contacted {
    /// A static body of the world.
    Static {
        /// The body's name.
        name: String,
        /// The body's label.
        label: TruthLabel,
    },
    /// Another, non-adjacent link of the robot.
    Link(String),
}

/// A robot link in contact with something.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Contact {
    /// The robot link.
    pub link: String,
    /// What it touches.
    pub with: Contacted,
}

impl fmt::Display for Contacted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Static { name, .. } => write!(f, "{name}"),
            Self::Link(link) => write!(f, "robot link {link}"),
        }
    }
}

impl fmt::Display for Contact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} touches {}", self.link, self.with)
    }
}
