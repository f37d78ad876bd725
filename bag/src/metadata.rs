//! rosbag2's `metadata.yaml` (format version 8): [`BagInfo`] written by hand (the file is
//! small and fixed-shape, so no YAML crate), and [`relative_file_paths`], the one key the
//! reader parses back.
//!
//! Version 8 with string QoS profiles is what both Humble and Jazzy parse (v9's list of
//! QoS maps breaks Humble). Every key of v8 is written: `version`, `storage_identifier`,
//! `duration`, `starting_time`, `message_count`, `topics_with_message_count` (name, type,
//! serialization_format, offered_qos_profiles, type_description_hash), `compression_format`,
//! `compression_mode`, `relative_file_paths`, `files`, `custom_data`, `ros_distro`.

use std::fmt::Write as _;

/// QoS of a latched topic (`/tf_static`, `/robot_description`) as a v8 YAML string:
/// reliable, transient-local, keep-last 1, infinite deadline/lifespan/lease (the values
/// rosbags writes).
pub const LATCHED_QOS_V8: &str = "- avoid_ros_namespace_conventions: false\n  deadline: {nsec: 4294967295, sec: 2147483647}\n  depth: 1\n  durability: 1\n  history: 1\n  lifespan: {nsec: 4294967295, sec: 2147483647}\n  liveliness: 1\n  liveliness_lease_duration: {nsec: 4294967295, sec: 2147483647}\n  reliability: 1";

/// One topic's entry of `topics_with_message_count`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicEntry {
    /// Topic name.
    pub name: String,
    /// `pkg/msg/Type`.
    pub type_name: String,
    /// The v8 QoS string (`''` for the player's default).
    pub offered_qos_profiles: String,
    /// `RIHS01_…` or empty.
    pub type_description_hash: String,
    /// Messages on the topic.
    pub message_count: u64,
}

/// What `metadata.yaml` says about a single-file MCAP bag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagInfo {
    /// The storage file, relative to the bag directory.
    pub file: String,
    /// Smallest log time, ns (0 for an empty bag).
    pub starting_time_ns: u64,
    /// Largest minus smallest log time, ns.
    pub duration_ns: u64,
    /// Every topic.
    pub topics: Vec<TopicEntry>,
}

/// A YAML double-quoted scalar.
fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

impl BagInfo {
    /// Total messages.
    pub fn message_count(&self) -> u64 {
        self.topics.iter().map(|t| t.message_count).sum()
    }

    /// The mapping under `rosbag2_bagfile_information`, unindented (what the MCAP
    /// `rosbag2` metadata record carries as `serialized_metadata`).
    ///
    /// ```
    /// use nbv_bag::metadata::BagInfo;
    /// let info = BagInfo { file: "b_0.mcap".into(), starting_time_ns: 5, duration_ns: 2, topics: vec![] };
    /// assert!(info.serialized().contains("relative_file_paths:\n- \"b_0.mcap\"\n"));
    /// assert!(info.to_yaml().starts_with("rosbag2_bagfile_information:\n  version: 8\n"));
    /// ```
    pub fn serialized(&self) -> String {
        let mut y = String::new();
        let count = self.message_count();
        let _ = writeln!(y, "version: 8");
        let _ = writeln!(y, "storage_identifier: mcap");
        let _ = writeln!(y, "duration:\n  nanoseconds: {}", self.duration_ns);
        let _ = writeln!(
            y,
            "starting_time:\n  nanoseconds_since_epoch: {}",
            self.starting_time_ns
        );
        let _ = writeln!(y, "message_count: {count}");
        if self.topics.is_empty() {
            let _ = writeln!(y, "topics_with_message_count: []");
        } else {
            let _ = writeln!(y, "topics_with_message_count:");
        }
        for t in &self.topics {
            let _ = writeln!(y, "- message_count: {}", t.message_count);
            let _ = writeln!(y, "  topic_metadata:");
            let _ = writeln!(y, "    name: {}", quoted(&t.name));
            let _ = writeln!(
                y,
                "    offered_qos_profiles: {}",
                quoted(&t.offered_qos_profiles)
            );
            let _ = writeln!(y, "    serialization_format: cdr");
            let _ = writeln!(y, "    type: {}", quoted(&t.type_name));
            let _ = writeln!(
                y,
                "    type_description_hash: {}",
                quoted(&t.type_description_hash)
            );
        }
        let _ = writeln!(y, "compression_format: ''");
        let _ = writeln!(y, "compression_mode: ''");
        let _ = writeln!(y, "relative_file_paths:\n- {}", quoted(&self.file));
        let _ = writeln!(y, "files:");
        let _ = writeln!(y, "- path: {}", quoted(&self.file));
        let _ = writeln!(
            y,
            "  starting_time:\n    nanoseconds_since_epoch: {}",
            self.starting_time_ns
        );
        let _ = writeln!(y, "  duration:\n    nanoseconds: {}", self.duration_ns);
        let _ = writeln!(y, "  message_count: {count}");
        let _ = writeln!(y, "custom_data: {{}}");
        let _ = writeln!(y, "ros_distro: nbv-bag");
        y
    }

    /// The whole `metadata.yaml`.
    pub fn to_yaml(&self) -> String {
        let mut out = String::from("rosbag2_bagfile_information:\n");
        for line in self.serialized().lines() {
            out.push_str("  ");
            out.push_str(line);
            out.push('\n');
        }
        out
    }
}

/// Undoes YAML quoting of a plain, single- or double-quoted scalar (the escapes this
/// module and rosbags write).
fn unquote(s: &str) -> String {
    let s = s.trim();
    if let Some(inner) = s.strip_prefix('\'').and_then(|r| r.strip_suffix('\'')) {
        return inner.replace("''", "'");
    }
    if let Some(inner) = s.strip_prefix('"').and_then(|r| r.strip_suffix('"')) {
        let mut out = String::new();
        let mut chars = inner.chars();
        while let Some(c) = chars.next() {
            if c == '\\' {
                match chars.next() {
                    Some('n') => out.push('\n'),
                    Some('t') => out.push('\t'),
                    Some(other) => out.push(other),
                    None => {}
                }
            } else {
                out.push(c);
            }
        }
        return out;
    }
    s.to_owned()
}

/// The `relative_file_paths` list of a `metadata.yaml` (block `- a` items or a flow
/// `[a, b]` list), or `None` when the key is absent.
///
/// ```
/// use nbv_bag::metadata::relative_file_paths;
/// let y = "rosbag2_bagfile_information:\n  relative_file_paths:\n  - bag_0.mcap\n  - 'bag_1.mcap'\n  version: 8\n";
/// assert_eq!(relative_file_paths(y), Some(vec!["bag_0.mcap".to_string(), "bag_1.mcap".to_string()]));
/// assert_eq!(relative_file_paths("a: 1"), None);
/// ```
pub fn relative_file_paths(yaml: &str) -> Option<Vec<String>> {
    let mut lines = yaml.lines();
    let rest = loop {
        let line = lines.next()?;
        if let Some(rest) = line.trim_start().strip_prefix("relative_file_paths:") {
            break rest.trim();
        }
    };
    if let Some(flow) = rest.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        return Some(
            flow.split(',')
                .map(unquote)
                .filter(|s| !s.is_empty())
                .collect(),
        );
    }
    let mut paths = Vec::new();
    for line in lines {
        match line.trim_start().strip_prefix("- ") {
            Some(item) => paths.push(unquote(item)),
            None => break,
        }
    }
    Some(paths)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaml_has_every_v8_key_and_counts() {
        let info = BagInfo {
            file: "run_0.mcap".into(),
            starting_time_ns: 100,
            duration_ns: 50,
            topics: vec![
                TopicEntry {
                    name: "/points".into(),
                    type_name: "sensor_msgs/msg/PointCloud2".into(),
                    offered_qos_profiles: String::new(),
                    type_description_hash: String::new(),
                    message_count: 2,
                },
                TopicEntry {
                    name: "/tf_static".into(),
                    type_name: "tf2_msgs/msg/TFMessage".into(),
                    offered_qos_profiles: LATCHED_QOS_V8.into(),
                    type_description_hash: String::new(),
                    message_count: 1,
                },
            ],
        };
        let y = info.to_yaml();
        for key in [
            "version: 8",
            "storage_identifier: mcap",
            "duration:\n    nanoseconds: 50",
            "starting_time:\n    nanoseconds_since_epoch: 100",
            "  message_count: 3\n  topics_with_message_count:",
            "compression_format: ''",
            "compression_mode: ''",
            "files:",
            "custom_data: {}",
            "ros_distro: nbv-bag",
            "type_description_hash: \"\"",
            "durability: 1\\n",
        ] {
            assert!(y.contains(key), "{key} missing in\n{y}");
        }
        assert_eq!(relative_file_paths(&y), Some(vec!["run_0.mcap".into()]));
    }

    #[test]
    fn quoting_round_trips() {
        for s in ["", "a\"b\\c", "x\ny\tz", LATCHED_QOS_V8] {
            assert_eq!(unquote(&quoted(s)), s);
        }
    }
}
