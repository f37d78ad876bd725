//! [`BagWriter`]: a rosbag2 directory with MCAP storage — `dir/<dirname>_0.mcap` (profile
//! `ros2`, zstd chunks, message/chunk indexes, statistics and summary: the `mcap` crate's
//! defaults) and `dir/metadata.yaml` (v8).
//!
//! Nothing partial on disk: the bag is written into a hidden sibling directory
//! (`.<dirname>.partial-<pid>-<n>`) that [`BagWriter::finish`] renames into place; a
//! writer dropped unfinished (or failing) removes it. [`BagWriter::create`] refuses an
//! existing `dir`; [`BagWriter::create_overwrite`] replaces it at `finish()` (removed
//! just before the rename, so a failed write leaves the old bag untouched).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use mcap::records::{MessageHeader, Metadata};
use mcap::{Compression, WriteOptions, Writer};

use crate::error::BagError;
use crate::messages::RosMessage;
use crate::metadata::{BagInfo, LATCHED_QOS_V8, TopicEntry};

/// Topics latched by ROS convention: registered with transient-local QoS when
/// [`BagWriter::write`] registers them implicitly.
pub const LATCHED_TOPICS: [&str; 2] = ["/tf_static", "/robot_description"];

static PARTIAL_COUNTER: AtomicUsize = AtomicUsize::new(0);

#[derive(Debug)]
struct Topic {
    channel_id: u16,
    entry: TopicEntry,
    sequence: u32,
}

/// Writes one bag. Register topics with [`add_topic`](Self::add_topic) (or let
/// [`write`](Self::write) do it), write messages, then [`finish`](Self::finish).
///
/// ```
/// use nbv_bag::messages::RosString;
/// use nbv_bag::{BagReader, BagWriter};
/// let tmp = tempfile::tempdir().unwrap();
/// let dir = tmp.path().join("run");
/// let mut bag = BagWriter::create(&dir).unwrap();
/// bag.write("/robot_description", 5, &RosString { data: "<robot/>".into() }).unwrap();
/// bag.finish().unwrap();
/// assert!(dir.join("run_0.mcap").is_file() && dir.join("metadata.yaml").is_file());
/// let reader = BagReader::open(&dir).unwrap();
/// assert_eq!(reader.topic("/robot_description").unwrap().message_count, 1);
/// assert!(BagWriter::create(&dir).is_err()); // exists
/// ```
pub struct BagWriter {
    dir: PathBuf,
    partial: PathBuf,
    file_name: String,
    overwrite: bool,
    mcap: Option<Writer<BufWriter<File>>>,
    topics: BTreeMap<String, Topic>,
    time_range: Option<(u64, u64)>,
}

impl std::fmt::Debug for BagWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BagWriter")
            .field("dir", &self.dir)
            .field("topics", &self.topics.keys().collect::<Vec<_>>())
            .finish_non_exhaustive()
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> BagError + '_ {
    move |source| BagError::Io {
        path: path.to_owned(),
        source,
    }
}

impl BagWriter {
    /// Starts a bag that will be the directory `dir`, which must not exist.
    ///
    /// # Errors
    /// [`BagError::Exists`], or [`BagError::Io`]/[`BagError::Mcap`] creating the files.
    pub fn create(dir: impl AsRef<Path>) -> Result<Self, BagError> {
        Self::start(dir.as_ref(), false)
    }

    /// Like [`create`](Self::create), but an existing `dir` is replaced at
    /// [`finish`](Self::finish).
    ///
    /// # Errors
    /// As [`create`](Self::create), less [`BagError::Exists`].
    pub fn create_overwrite(dir: impl AsRef<Path>) -> Result<Self, BagError> {
        Self::start(dir.as_ref(), true)
    }

    fn start(dir: &Path, overwrite: bool) -> Result<Self, BagError> {
        let dir = std::path::absolute(dir).map_err(io_err(dir))?;
        if !overwrite && dir.exists() {
            return Err(BagError::Exists { path: dir });
        }
        let name = dir
            .file_name()
            .and_then(|n| n.to_str())
            .filter(|n| !n.is_empty())
            .ok_or_else(|| BagError::Layout {
                path: dir.clone(),
                message: "a bag directory needs a UTF-8 name".into(),
            })?
            .to_owned();
        let parent = dir.parent().unwrap_or(Path::new("/"));
        std::fs::create_dir_all(parent).map_err(io_err(parent))?;
        let n = PARTIAL_COUNTER.fetch_add(1, Ordering::Relaxed);
        let partial = parent.join(format!(".{name}.partial-{}-{n}", std::process::id()));
        if partial.exists() {
            std::fs::remove_dir_all(&partial).map_err(io_err(&partial))?;
        }
        std::fs::create_dir(&partial).map_err(io_err(&partial))?;
        let file_name = format!("{name}_0.mcap");
        let mcap_path = partial.join(&file_name);
        let opened = File::create(&mcap_path)
            .map_err(io_err(&mcap_path))
            .and_then(|f| {
                WriteOptions::new()
                    .profile("ros2")
                    .compression(Some(Compression::Zstd))
                    .create(BufWriter::new(f))
                    .map_err(|source| BagError::Mcap {
                        path: dir.join(&file_name),
                        source,
                    })
            });
        let mcap = match opened {
            Ok(m) => m,
            Err(e) => {
                let _ = std::fs::remove_dir_all(&partial);
                return Err(e);
            }
        };
        Ok(Self {
            dir,
            partial,
            file_name,
            overwrite,
            mcap: Some(mcap),
            topics: BTreeMap::new(),
            time_range: None,
        })
    }

    fn mcap_error(&self, source: mcap::McapError) -> BagError {
        BagError::Mcap {
            path: self.dir.join(&self.file_name),
            source,
        }
    }

    /// Registers `topic` as type `M`; `latched` gives it transient-local QoS (for
    /// `/tf_static`, `/robot_description`). Registering again with the same type is a
    /// no-op.
    ///
    /// # Errors
    /// [`BagError::TopicType`] if the topic has another type; [`BagError::Mcap`].
    pub fn add_topic<M: RosMessage>(&mut self, topic: &str, latched: bool) -> Result<(), BagError> {
        self.add_topic_raw(
            topic,
            M::TYPE_NAME,
            &M::schema_text(),
            M::TYPE_HASH,
            latched,
        )
    }

    /// Registers a topic of any type from its `ros2msg` schema text (for types this crate
    /// has no struct for; `type_hash` may be empty).
    ///
    /// # Errors
    /// As [`add_topic`](Self::add_topic).
    pub fn add_topic_raw(
        &mut self,
        topic: &str,
        type_name: &str,
        schema_text: &str,
        type_hash: &str,
        latched: bool,
    ) -> Result<(), BagError> {
        if let Some(t) = self.topics.get(topic) {
            if t.entry.type_name == type_name {
                return Ok(());
            }
            return Err(BagError::TopicType {
                path: self.dir.clone(),
                topic: topic.into(),
                actual: t.entry.type_name.clone(),
                requested: type_name.into(),
            });
        }
        let qos = if latched { LATCHED_QOS_V8 } else { "" };
        let Some(mcap) = self.mcap.as_mut() else {
            return Err(self.mcap_error(mcap::McapError::UnexpectedEof));
        };
        let registered = mcap
            .add_schema(type_name, "ros2msg", schema_text.as_bytes())
            .and_then(|schema_id| {
                let metadata =
                    BTreeMap::from([("offered_qos_profiles".to_owned(), qos.to_owned())]);
                mcap.add_channel(schema_id, topic, "cdr", &metadata)
            });
        let channel_id = registered.map_err(|e| self.mcap_error(e))?;
        self.topics.insert(
            topic.to_owned(),
            Topic {
                channel_id,
                entry: TopicEntry {
                    name: topic.to_owned(),
                    type_name: type_name.to_owned(),
                    offered_qos_profiles: qos.to_owned(),
                    type_description_hash: type_hash.to_owned(),
                    message_count: 0,
                },
                sequence: 0,
            },
        );
        Ok(())
    }

    /// Writes `msg` on `topic` at log time `stamp_ns` (registering the topic if needed,
    /// latched if it is one of [`LATCHED_TOPICS`]).
    ///
    /// # Errors
    /// [`BagError::TopicType`] if the topic has another type; [`BagError::Mcap`].
    pub fn write<M: RosMessage>(
        &mut self,
        topic: &str,
        stamp_ns: u64,
        msg: &M,
    ) -> Result<(), BagError> {
        self.add_topic::<M>(topic, LATCHED_TOPICS.contains(&topic))?;
        self.write_raw(topic, stamp_ns, &msg.encode())
    }

    /// Writes CDR bytes on a registered topic at log time `stamp_ns`.
    ///
    /// # Errors
    /// [`BagError::UnknownTopic`] for a topic not registered; [`BagError::Mcap`].
    pub fn write_raw(&mut self, topic: &str, stamp_ns: u64, cdr: &[u8]) -> Result<(), BagError> {
        let Some(t) = self.topics.get_mut(topic) else {
            return Err(BagError::UnknownTopic {
                path: self.dir.clone(),
                topic: topic.into(),
            });
        };
        t.sequence = t.sequence.wrapping_add(1);
        let header = MessageHeader {
            channel_id: t.channel_id,
            sequence: t.sequence,
            log_time: stamp_ns,
            publish_time: stamp_ns,
        };
        let written = match self.mcap.as_mut() {
            Some(m) => m.write_to_known_channel(&header, cdr),
            None => Err(mcap::McapError::UnexpectedEof),
        };
        if let Err(source) = written {
            return Err(BagError::Mcap {
                path: self.dir.join(&self.file_name),
                source,
            });
        }
        t.entry.message_count += 1;
        self.time_range = Some(match self.time_range {
            None => (stamp_ns, stamp_ns),
            Some((a, b)) => (a.min(stamp_ns), b.max(stamp_ns)),
        });
        Ok(())
    }

    /// The metadata as it stands.
    fn info(&self) -> BagInfo {
        let (start, end) = self.time_range.unwrap_or((0, 0));
        BagInfo {
            file: self.file_name.clone(),
            starting_time_ns: start,
            duration_ns: end - start,
            topics: self.topics.values().map(|t| t.entry.clone()).collect(),
        }
    }

    /// Finishes the MCAP file (metadata record, summary, footer), writes `metadata.yaml`
    /// and moves the bag into place. Returns the bag directory.
    ///
    /// # Errors
    /// [`BagError::Mcap`], [`BagError::Io`], or [`BagError::Exists`] if `dir` appeared
    /// meanwhile (without overwrite); the partial directory is removed.
    pub fn finish(mut self) -> Result<PathBuf, BagError> {
        let info = self.info();
        let mcap_result = match self.mcap.take() {
            Some(mut m) => m
                .write_metadata(&Metadata {
                    name: "rosbag2".into(),
                    metadata: BTreeMap::from([(
                        "serialized_metadata".to_owned(),
                        info.serialized().trim_end().to_owned(),
                    )]),
                })
                .and_then(|()| m.finish().map(|_| ()))
                .map(|()| m.into_inner()),
            None => Err(mcap::McapError::UnexpectedEof),
        };
        let mut file = mcap_result.map_err(|e| self.mcap_error(e))?;
        let mcap_path = self.partial.join(&self.file_name);
        file.flush().map_err(io_err(&mcap_path))?;
        drop(file);
        let yaml_path = self.partial.join("metadata.yaml");
        std::fs::write(&yaml_path, info.to_yaml()).map_err(io_err(&yaml_path))?;
        if self.dir.exists() {
            if !self.overwrite {
                return Err(BagError::Exists {
                    path: self.dir.clone(),
                });
            }
            std::fs::remove_dir_all(&self.dir).map_err(io_err(&self.dir))?;
        }
        std::fs::rename(&self.partial, &self.dir).map_err(io_err(&self.dir))?;
        Ok(self.dir.clone())
    }
}

impl Drop for BagWriter {
    fn drop(&mut self) {
        drop(self.mcap.take());
        if self.partial.exists() {
            let _ = std::fs::remove_dir_all(&self.partial);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{Header, RosString};

    #[test]
    fn unfinished_leaves_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("bag");
        {
            let mut w = BagWriter::create(&dir).unwrap();
            w.write("/s", 1, &RosString::default()).unwrap();
        }
        assert!(!dir.exists());
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    }

    #[test]
    fn type_clash_and_unknown_topic() {
        let tmp = tempfile::tempdir().unwrap();
        let mut w = BagWriter::create(tmp.path().join("b")).unwrap();
        w.write("/s", 1, &RosString::default()).unwrap();
        let e = w.write("/s", 2, &Header::default()).unwrap_err();
        assert!(
            e.to_string()
                .contains("topic /s has type std_msgs/msg/String, not std_msgs/msg/Header"),
            "{e}"
        );
        assert!(matches!(
            w.write_raw("/nope", 1, &[0, 1, 0, 0]),
            Err(BagError::UnknownTopic { .. })
        ));
    }

    #[test]
    fn overwrite_replaces() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("b");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join("old.txt"), "x").unwrap();
        assert!(matches!(
            BagWriter::create(&dir),
            Err(BagError::Exists { .. })
        ));
        let w = BagWriter::create_overwrite(&dir).unwrap();
        assert!(dir.join("old.txt").exists());
        w.finish().unwrap();
        assert!(!dir.join("old.txt").exists());
        let yaml = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
        assert!(yaml.contains("message_count: 0"));
        assert!(yaml.contains("b_0.mcap"));
    }
}
