//! [`BagReader`]: opens a rosbag2 directory (MCAP storage; the files listed in
//! `metadata.yaml`'s `relative_file_paths`, else the single `*.mcap` inside) or a bare
//! `.mcap` file, lists its topics and yields a topic's messages in log-time order; with
//! helpers for the tf tree ([`BagReader::tf_buffer`]) and xyz clouds
//! ([`BagReader::point_clouds`]).
//!
//! Whole files are read into memory and every message is taken out of the MCAP once, at
//! [`open`](BagReader::open) (by `mcap_scan`, which also keeps malformed input from
//! panicking inside the `mcap` crate): CRCs are checked (chunk CRCs too) and a corrupt or
//! truncated file is an error there. Messages are decoded from CDR only when asked for.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::Point3;

use crate::error::{BagError, DecodeError};
use crate::mcap_scan;
use crate::messages::{Header, PointCloud2, RosMessage, TFMessage};
use crate::metadata::relative_file_paths;
use crate::point_cloud::cloud_xyz;
use crate::tf_buffer::TfBuffer;

/// A topic of the bag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    /// Its name.
    pub name: String,
    /// Its type, `pkg/msg/Type` (the MCAP schema name).
    pub type_name: String,
    /// The channel's message encoding (`cdr` in a ROS 2 bag).
    pub message_encoding: String,
    /// The channel's `offered_qos_profiles` metadata (may be empty).
    pub offered_qos_profiles: String,
    /// Messages on it, over all files.
    pub message_count: usize,
}

/// One message: its index in the topic (log-time order, from 0), its log time and its
/// CDR bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagMessage {
    /// Index in the topic.
    pub index: usize,
    /// Log time, ns.
    pub log_time_ns: u64,
    /// The serialized message.
    pub data: Vec<u8>,
}

/// A decoded cloud: its header, its log time and its finite points (in
/// `header.frame_id`).
#[derive(Debug, Clone, PartialEq)]
pub struct StampedCloud {
    /// Index in the topic.
    pub index: usize,
    /// Log time, ns.
    pub log_time_ns: u64,
    /// The cloud's header (stamp and sensor frame).
    pub header: Header,
    /// The finite points.
    pub points: Vec<Point3<f64>>,
}

#[derive(Debug)]
struct Stored {
    log_time_ns: u64,
    file: usize,
    data: Vec<u8>,
}

/// A bag read into memory.
///
/// ```
/// use nbv_bag::{BagReader, BagWriter, messages::Header, point_cloud::cloud_from_points};
/// let tmp = tempfile::tempdir().unwrap();
/// let mut w = BagWriter::create(tmp.path().join("b")).unwrap();
/// let header = Header { frame_id: "sensor".into(), ..Default::default() };
/// w.write("/points", 7, &cloud_from_points(header, &[[1.0, 2.0, 3.0]])).unwrap();
/// let dir = w.finish().unwrap();
/// let bag = BagReader::open(&dir).unwrap();
/// let clouds = bag.point_clouds("/points").unwrap();
/// assert_eq!((clouds[0].log_time_ns, clouds[0].points.len()), (7, 1));
/// ```
#[derive(Debug)]
pub struct BagReader {
    files: Vec<PathBuf>,
    topics: BTreeMap<String, TopicInfo>,
    messages: BTreeMap<String, Vec<Stored>>,
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> BagError + '_ {
    move |source| BagError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The storage files of a bag directory.
fn storage_files(dir: &Path) -> Result<Vec<PathBuf>, BagError> {
    let yaml_path = dir.join("metadata.yaml");
    if yaml_path.is_file() {
        let yaml = std::fs::read_to_string(&yaml_path).map_err(io_err(&yaml_path))?;
        if let Some(paths) = relative_file_paths(&yaml) {
            if paths.is_empty() {
                return Err(BagError::Layout {
                    path: yaml_path,
                    message: "relative_file_paths is empty".into(),
                });
            }
            return Ok(paths.iter().map(|p| dir.join(p)).collect());
        }
    }
    let mut mcaps: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io_err(dir))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .collect();
    mcaps.sort();
    match mcaps.len() {
        1 => Ok(mcaps),
        n => Err(BagError::Layout {
            path: dir.to_owned(),
            message: format!(
                "no metadata.yaml with relative_file_paths, and {n} .mcap files (need exactly 1)"
            ),
        }),
    }
}

impl BagReader {
    /// Opens a bag directory or a bare `.mcap` file.
    ///
    /// # Errors
    /// [`BagError::Io`], [`BagError::Layout`] (no storage file), [`BagError::Mcap`]
    /// (corrupt, truncated, bad CRC), [`BagError::Profile`] (not `ros2`).
    pub fn open(path: impl AsRef<Path>) -> Result<Self, BagError> {
        let path = path.as_ref();
        let files = if path.is_dir() {
            storage_files(path)?
        } else {
            vec![path.to_owned()]
        };
        let mut contents = Vec::with_capacity(files.len());
        for f in files {
            let bytes = std::fs::read(&f).map_err(io_err(&f))?;
            contents.push((f, bytes));
        }
        Self::from_files(contents)
    }

    /// Reads MCAP bytes already in memory; `path` only names them in errors.
    ///
    /// # Errors
    /// As [`open`](Self::open).
    pub fn from_mcap_bytes(path: impl Into<PathBuf>, bytes: &[u8]) -> Result<Self, BagError> {
        let mut reader = Self {
            files: Vec::new(),
            topics: BTreeMap::new(),
            messages: BTreeMap::new(),
        };
        reader.add_file(path.into(), bytes)?;
        reader.sort();
        Ok(reader)
    }

    fn from_files(files: Vec<(PathBuf, Vec<u8>)>) -> Result<Self, BagError> {
        let mut reader = Self {
            files: Vec::new(),
            topics: BTreeMap::new(),
            messages: BTreeMap::new(),
        };
        for (path, bytes) in files {
            reader.add_file(path, &bytes)?;
        }
        reader.sort();
        Ok(reader)
    }

    fn sort(&mut self) {
        for v in self.messages.values_mut() {
            v.sort_by_key(|m| m.log_time_ns); // stable: file order among equal times
        }
    }

    fn add_file(&mut self, path: PathBuf, bytes: &[u8]) -> Result<(), BagError> {
        let scan = mcap_scan::scan(bytes).map_err(|source| BagError::Mcap {
            path: path.clone(),
            source,
        })?;
        if scan.profile != "ros2" {
            return Err(BagError::Profile {
                path,
                profile: scan.profile,
            });
        }
        let file = self.files.len();
        for c in scan.channels.values() {
            self.topics
                .entry(c.topic.clone())
                .or_insert_with(|| TopicInfo {
                    name: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    message_encoding: c.message_encoding.clone(),
                    offered_qos_profiles: c
                        .metadata
                        .get("offered_qos_profiles")
                        .cloned()
                        .unwrap_or_default(),
                    message_count: 0,
                });
        }
        for m in scan.messages {
            if let Some(info) = self.topics.get_mut(&m.topic) {
                info.message_count += 1;
            }
            self.messages.entry(m.topic).or_default().push(Stored {
                log_time_ns: m.log_time,
                file,
                data: m.data,
            });
        }
        self.files.push(path);
        Ok(())
    }

    /// The storage files read.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// Every topic, by name.
    pub fn topics(&self) -> impl Iterator<Item = &TopicInfo> {
        self.topics.values()
    }

    /// One topic.
    pub fn topic(&self, name: &str) -> Option<&TopicInfo> {
        self.topics.get(name)
    }

    fn bag_path(&self) -> PathBuf {
        self.files.first().cloned().unwrap_or_default()
    }

    fn checked_topic(&self, topic: &str) -> Result<&TopicInfo, BagError> {
        let info = self
            .topics
            .get(topic)
            .ok_or_else(|| BagError::UnknownTopic {
                path: self.bag_path(),
                topic: topic.into(),
            })?;
        if info.message_encoding != "cdr" {
            return Err(BagError::Encoding {
                path: self.bag_path(),
                topic: topic.into(),
                encoding: info.message_encoding.clone(),
            });
        }
        Ok(info)
    }

    /// The messages of `topic` in log-time order.
    ///
    /// # Errors
    /// [`BagError::UnknownTopic`]; [`BagError::Encoding`] if the topic is not CDR.
    pub fn messages(&self, topic: &str) -> Result<impl Iterator<Item = BagMessage> + '_, BagError> {
        self.checked_topic(topic)?;
        let stored = self.messages.get(topic).map_or(&[][..], Vec::as_slice);
        Ok(stored.iter().enumerate().map(|(index, m)| BagMessage {
            index,
            log_time_ns: m.log_time_ns,
            data: m.data.clone(),
        }))
    }

    /// The messages of `topic` decoded as `M`, with their log times.
    ///
    /// # Errors
    /// As [`messages`](Self::messages); [`BagError::TopicType`] if the topic is not an
    /// `M`; [`BagError::Message`] naming the file, topic and index of a message that does
    /// not decode.
    pub fn read<M: RosMessage>(&self, topic: &str) -> Result<Vec<(u64, M)>, BagError> {
        let info = self.checked_topic(topic)?;
        if info.type_name != M::TYPE_NAME {
            return Err(BagError::TopicType {
                path: self.bag_path(),
                topic: topic.into(),
                actual: info.type_name.clone(),
                requested: M::TYPE_NAME.into(),
            });
        }
        let stored = self.messages.get(topic).map_or(&[][..], Vec::as_slice);
        stored
            .iter()
            .enumerate()
            .map(|(index, m)| {
                M::decode(&m.data)
                    .map(|msg| (m.log_time_ns, msg))
                    .map_err(|e| self.message_error(topic, index, m.file, e.into()))
            })
            .collect()
    }

    fn message_error(
        &self,
        topic: &str,
        index: usize,
        file: usize,
        source: DecodeError,
    ) -> BagError {
        BagError::Message {
            path: self.files.get(file).cloned().unwrap_or_default(),
            topic: topic.into(),
            index,
            source,
        }
    }

    /// A tf buffer of every transform on `/tf` (dynamic) and `/tf_static` (static);
    /// either topic may be absent.
    ///
    /// # Errors
    /// As [`read`](Self::read) for those topics.
    pub fn tf_buffer(&self) -> Result<TfBuffer, BagError> {
        let mut buffer = TfBuffer::new();
        for (topic, is_static) in [("/tf_static", true), ("/tf", false)] {
            if self.topics.contains_key(topic) {
                for (_, msg) in self.read::<TFMessage>(topic)? {
                    buffer.insert(&msg, is_static);
                }
            }
        }
        Ok(buffer)
    }

    /// The clouds of a `sensor_msgs/msg/PointCloud2` topic as finite xyz points.
    ///
    /// # Errors
    /// As [`read`](Self::read); [`BagError::Message`] for a cloud whose layout cannot be
    /// read (e.g. "bag/run_0.mcap: topic /points message 3: point cloud data is 100 bytes,
    /// row_step×height says 120").
    pub fn point_clouds(&self, topic: &str) -> Result<Vec<StampedCloud>, BagError> {
        let clouds = self.read::<PointCloud2>(topic)?;
        let stored = self.messages.get(topic).map_or(&[][..], Vec::as_slice);
        clouds
            .into_iter()
            .zip(stored)
            .enumerate()
            .map(|(index, ((log_time_ns, cloud), m))| {
                let points = cloud_xyz(&cloud)
                    .map_err(|e| self.message_error(topic, index, m.file, e.into()))?;
                Ok(StampedCloud {
                    index,
                    log_time_ns,
                    header: cloud.header,
                    points,
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{PointCloud2, RosString};
    use crate::point_cloud::cloud_from_points;
    use crate::writer::BagWriter;

    #[test]
    fn bad_cloud_error_names_file_topic_and_index() {
        let tmp = tempfile::tempdir().unwrap();
        let mut w = BagWriter::create(tmp.path().join("run")).unwrap();
        for i in 0..4u64 {
            let mut c = cloud_from_points(Header::default(), &[[1.0, 2.0, 3.0]; 10]);
            if i == 3 {
                c.data.truncate(100);
                c.row_step = 120;
            }
            w.write("/points", 10 - i, &c).unwrap(); // reverse log-time order
        }
        let dir = w.finish().unwrap();
        let bag = BagReader::open(&dir).unwrap();
        let e = bag.point_clouds("/points").unwrap_err();
        let file = dir.join("run_0.mcap");
        assert_eq!(
            e.to_string(),
            format!(
                "{}: topic /points message 0: point cloud data is 100 bytes, row_step×height says 120",
                file.display()
            )
        );
        let times: Vec<u64> = bag
            .messages("/points")
            .unwrap()
            .map(|m| m.log_time_ns)
            .collect();
        assert_eq!(times, vec![7, 8, 9, 10]);
        assert!(matches!(
            bag.read::<RosString>("/points"),
            Err(BagError::TopicType { .. })
        ));
        assert!(matches!(
            bag.messages("/nope"),
            Err(BagError::UnknownTopic { .. })
        ));
        let _ = PointCloud2::TYPE_NAME;
    }

    #[test]
    fn profile_must_be_ros2() {
        let mut buf = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new().create(&mut buf).unwrap();
        w.finish().unwrap();
        drop(w);
        let e = BagReader::from_mcap_bytes("x.mcap", buf.get_ref()).unwrap_err();
        assert_eq!(e.to_string(), "x.mcap: MCAP profile is '', expected 'ros2'");
    }

    #[test]
    fn encoding_must_be_cdr() {
        let mut buf = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .create(&mut buf)
            .unwrap();
        let s = w
            .add_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
            .unwrap();
        let c = w.add_channel(s, "/j", "json", &BTreeMap::new()).unwrap();
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: c,
                sequence: 0,
                log_time: 1,
                publish_time: 1,
            },
            b"{}",
        )
        .unwrap();
        w.finish().unwrap();
        drop(w);
        let bag = BagReader::from_mcap_bytes("x.mcap", buf.get_ref()).unwrap();
        assert_eq!(bag.topic("/j").unwrap().message_count, 1);
        let e = bag.messages("/j").err().unwrap();
        assert_eq!(
            e.to_string(),
            "x.mcap: topic /j: message encoding is 'json', expected 'cdr'"
        );
    }
}
