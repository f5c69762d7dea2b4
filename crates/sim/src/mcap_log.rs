//! The MCAP convention of every scenario (`crates/sim/README.md`, "MCAP logs"): JSON messages
//! with `jsonschema` schemas (zstd chunks), read by Foxglove and the Python `mcap` package.
//!
//! * Topics `/<scenario>/<run>/<quantity>`; every run's log time starts at 0 (its first
//!   sample), runs are overlaid and told apart by their topic prefix.
//! * Schema names `deflect.<Type>` ([`Kind`]), the same field set wherever they appear, SI
//!   units in every numeric field, declared in the property's `description` (the schemas
//!   in the private `schema`).
//! * Foxglove's well-known schemas for the 3D panel: `foxglove.PosesInFrame` (the TCP pose,
//!   every sample) and `foxglove.SceneUpdate` (desired and actual paths as lines, one message
//!   at t = 0), frame `base`.
//! * One metadata record `deflect.run` per run ([`RunInfo`], [`RUN_METADATA_KEYS`]).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};
use serde_json::{Value, json};

use crate::SimError;

mod schema;

/// The frame of every position and pose: the robot's base frame.
pub const FRAME: &str = "base";

/// Name of the per-run metadata record.
pub const RUN_METADATA: &str = "deflect.run";

/// Keys of every `deflect.run` metadata record (values are strings).
pub const RUN_METADATA_KEYS: [&str; 12] = [
    "scenario",
    "run",
    "topic_prefix",
    "robot",
    "motion",
    "acceleration",
    "correction",
    "deflect_version",
    "command_line",
    "time_base",
    "units",
    "options",
];

/// What the time base is, as written in every `deflect.run` record.
pub const TIME_BASE: &str = "log time = simulated time since the run's first sample [s]; \
                             every run starts at t = 0, runs are told apart by topic prefix";

/// What the units are, as written in every `deflect.run` record.
pub const UNITS: &str = "SI: m, rad, N, N m, s; each field's unit in its schema's description";

/// The message types of the logs: `deflect.<Type>` and the Foxglove schemas used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A point `x, y, z` \[m\] (desired, commanded, actual, recorded points).
    Point,
    /// A pose: position `x, y, z` \[m\] and unit quaternion `qx, qy, qz, qw` \[1\].
    Pose,
    /// A force `fx, fy, fz` \[N\].
    Force,
    /// A wrench: force `fx, fy, fz` \[N\], moment `mx, my, mz` \[N m\].
    Wrench,
    /// A small 6-D displacement: `dx, dy, dz` \[m\], rotation vector `rx, ry, rz` \[rad\].
    Displacement,
    /// Joint angles \[rad\]: `command`, `motor`, `link` (arrays, one value per joint).
    JointState,
    /// Distance of the tool point from the desired path, `distance` \[m\].
    PathError,
    /// Pilot-control weight of the offline force estimate, `weight` \[1\].
    PilotControl,
    /// A state machine's state, `state` (text).
    TracerState,
    /// The cutter's engagement with the material: axial `depth` \[m\], engaged angles
    /// `entry_angle`, `exit_angle` \[rad\] (Altintas' immersion angles: clockwise from the
    /// tool frame's +y with the feed along +x), number of engaged `arcs`.
    Engagement,
    /// `foxglove.PosesInFrame`.
    PosesInFrame,
    /// `foxglove.SceneUpdate` (lines only).
    SceneUpdate,
}

/// Every [`Kind`].
pub const KINDS: [Kind; 12] = [
    Kind::Point,
    Kind::Pose,
    Kind::Force,
    Kind::Wrench,
    Kind::Displacement,
    Kind::JointState,
    Kind::PathError,
    Kind::PilotControl,
    Kind::TracerState,
    Kind::Engagement,
    Kind::PosesInFrame,
    Kind::SceneUpdate,
];

impl Kind {
    /// The schema name: `deflect.<Type>` or `foxglove.<Type>`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Point => "deflect.Point",
            Self::Pose => "deflect.Pose",
            Self::Force => "deflect.Force",
            Self::Wrench => "deflect.Wrench",
            Self::Displacement => "deflect.Displacement",
            Self::JointState => "deflect.JointState",
            Self::PathError => "deflect.PathError",
            Self::PilotControl => "deflect.PilotControl",
            Self::TracerState => "deflect.TracerState",
            Self::Engagement => "deflect.Engagement",
            Self::PosesInFrame => "foxglove.PosesInFrame",
            Self::SceneUpdate => "foxglove.SceneUpdate",
        }
    }

    /// The JSON schema (root an object; units in the descriptions).
    pub fn schema(self) -> Value {
        match self {
            Self::Point => schema::point(),
            Self::Pose => schema::pose(),
            Self::Force => schema::force(),
            Self::Wrench => schema::wrench(),
            Self::Displacement => schema::displacement(),
            Self::JointState => schema::joint_state(),
            Self::PathError => schema::path_error(),
            Self::PilotControl => schema::pilot_control(),
            Self::TracerState => schema::tracer_state(),
            Self::Engagement => schema::engagement(),
            Self::PosesInFrame => schema::poses_in_frame(),
            Self::SceneUpdate => schema::scene_update(),
        }
    }
}

/// Log time `t` \[s\] in nanoseconds (0 for negative or NaN times).
pub fn nanos(t: f64) -> u64 {
    let ns = (t * 1e9).round();
    if ns > 0.0 { ns as u64 } else { 0 }
}

/// A message timestamp `{"sec", "nsec"}` for time `t` \[s\].
pub fn stamp(t: f64) -> Value {
    let ns = nanos(t);
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

/// A `deflect.Point` message.
pub fn point(run: &str, t: f64, p: [f64; 3]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "x": p[0], "y": p[1], "z": p[2]})
}

/// A `deflect.Pose` message: position \[m\], quaternion `[x, y, z, w]`.
pub fn pose(run: &str, t: f64, p: [f64; 3], q: [f64; 4]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "x": p[0], "y": p[1], "z": p[2],
           "qx": q[0], "qy": q[1], "qz": q[2], "qw": q[3]})
}

/// A `deflect.Force` message \[N\].
pub fn force(run: &str, t: f64, f: [f64; 3]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "fx": f[0], "fy": f[1], "fz": f[2]})
}

/// A `deflect.Wrench` message \[N, N m\].
pub fn wrench(run: &str, t: f64, w: &[f64; 6]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "fx": w[0], "fy": w[1], "fz": w[2],
           "mx": w[3], "my": w[4], "mz": w[5]})
}

/// A `deflect.Displacement` message \[m, rad\].
pub fn displacement(run: &str, t: f64, d: &[f64; 6]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "dx": d[0], "dy": d[1], "dz": d[2],
           "rx": d[3], "ry": d[4], "rz": d[5]})
}

/// A `deflect.JointState` message \[rad\].
pub fn joints(run: &str, t: f64, command: &[f64], motor: &[f64], link: &[f64]) -> Value {
    json!({"timestamp": stamp(t), "run": run, "command": command, "motor": motor, "link": link})
}

/// A `deflect.PathError` message \[m\].
pub fn path_error(run: &str, t: f64, distance: f64) -> Value {
    json!({"timestamp": stamp(t), "run": run, "distance": distance})
}

/// A `deflect.PilotControl` message.
pub fn pilot(run: &str, t: f64, weight: f64) -> Value {
    json!({"timestamp": stamp(t), "run": run, "weight": weight})
}

/// A `deflect.Engagement` message: `depth` \[m\], `entry_angle`, `exit_angle` \[rad\], `arcs`.
pub fn engagement(run: &str, t: f64, depth: f64, angles: [f64; 2], arcs: usize) -> Value {
    json!({"timestamp": stamp(t), "run": run, "depth": depth, "entry_angle": angles[0],
           "exit_angle": angles[1], "arcs": arcs})
}

/// A `deflect.TracerState` message.
pub fn tracer_state(run: &str, t: f64, state: &str) -> Value {
    json!({"timestamp": stamp(t), "run": run, "state": state})
}

fn fox_pose(p: [f64; 3], q: [f64; 4]) -> Value {
    json!({"position": {"x": p[0], "y": p[1], "z": p[2]},
           "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}})
}

/// The identity quaternion `[x, y, z, w]`.
pub const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

/// A `foxglove.PosesInFrame` message of one pose in [`FRAME`].
pub fn poses_in_frame(t: f64, p: [f64; 3], q: [f64; 4]) -> Value {
    json!({"timestamp": stamp(t), "frame_id": FRAME, "poses": [fox_pose(p, q)]})
}

/// A path drawn as a line strip in a `foxglove.SceneUpdate`.
#[derive(Debug, Clone)]
pub struct Line {
    /// Entity id, e.g. "oc_gu_y-line_5g_corr/actual".
    pub id: String,
    /// Points \[m\], base frame.
    pub points: Vec<[f64; 3]>,
    /// Colour (RGB, 0-255; the plots' palette).
    pub rgb: (u8, u8, u8),
    /// Closed loop (an outline) rather than a strip.
    pub closed: bool,
}

/// A `foxglove.SceneUpdate` message at `t` with one entity per line, kept until replaced.
pub fn scene_update(t: f64, lines: &[Line]) -> Value {
    let ch = |c: u8| f64::from(c) / 255.0;
    let entities: Vec<Value> = lines
        .iter()
        .map(|l| {
            let points: Vec<Value> = l
                .points
                .iter()
                .map(|p| json!({"x": p[0], "y": p[1], "z": p[2]}))
                .collect();
            json!({
                "timestamp": stamp(t), "frame_id": FRAME, "id": l.id,
                "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": false,
                "metadata": [], "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
                "triangles": [], "texts": [], "models": [],
                "lines": [{
                    "type": if l.closed { 1 } else { 0 },
                    "pose": fox_pose([0.0; 3], IDENTITY),
                    "thickness": 2.0, "scale_invariant": true,
                    "points": points,
                    "color": {"r": ch(l.rgb.0), "g": ch(l.rgb.1), "b": ch(l.rgb.2), "a": 1.0},
                    "colors": [], "indices": []
                }]
            })
        })
        .collect();
    json!({"deletions": [], "entities": entities})
}

/// What a run was, for its `deflect.run` metadata record.
#[derive(Debug, Clone, Default)]
pub struct RunInfo {
    /// The command: "reproduce", "run", "milling", "contour", "serial".
    pub scenario: String,
    /// The run's name (the topic segment after the scenario).
    pub run: String,
    /// The robot in words.
    pub robot: String,
    /// The motion in words, with sizes and units.
    pub motion: String,
    /// The acceleration in words, with units.
    pub acceleration: String,
    /// The correction or compensation in words ("none" if off).
    pub correction: String,
    /// The scenario's settings (JSON).
    pub options: Value,
}

impl RunInfo {
    /// The topic prefix `/<scenario>/<run>/`.
    pub fn prefix(&self) -> String {
        format!("/{}/{}/", self.scenario, self.run)
    }

    /// The metadata record's map: [`RUN_METADATA_KEYS`], strings.
    pub fn metadata(&self) -> BTreeMap<String, String> {
        let command_line: Vec<String> = std::env::args().collect();
        let values = [
            self.scenario.clone(),
            self.run.clone(),
            self.prefix(),
            self.robot.clone(),
            self.motion.clone(),
            self.acceleration.clone(),
            self.correction.clone(),
            env!("CARGO_PKG_VERSION").to_string(),
            command_line.join(" "),
            TIME_BASE.to_string(),
            UNITS.to_string(),
            self.options.to_string(),
        ];
        RUN_METADATA_KEYS
            .iter()
            .map(|k| (*k).to_string())
            .zip(values)
            .collect()
    }
}

/// An MCAP file of JSON messages with JSON schemas (zstd chunks) following the convention.
pub struct McapLog {
    w: mcap::Writer<BufWriter<File>>,
    schemas: BTreeMap<Kind, u16>,
    seq: BTreeMap<u16, u32>,
    count: usize,
    path: PathBuf,
}

impl std::fmt::Debug for McapLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapLog")
            .field("path", &self.path)
            .field("count", &self.count)
            .finish_non_exhaustive()
    }
}

impl McapLog {
    /// Creates the file at `path`.
    pub fn create(path: &Path) -> Result<Self, SimError> {
        let err = |e: &dyn std::fmt::Display| SimError::file(path, "create the MCAP log", e);
        let file = File::create(path).map_err(|e| err(&e))?;
        Ok(Self {
            w: mcap::Writer::new(BufWriter::new(file)).map_err(|e| err(&e))?,
            schemas: BTreeMap::new(),
            seq: BTreeMap::new(),
            count: 0,
            path: path.to_path_buf(),
        })
    }

    fn err(&self, e: mcap::McapError) -> SimError {
        SimError::file(&self.path, "write the MCAP log", e)
    }

    /// Writes the `deflect.run` metadata record of `info`.
    pub fn run_metadata(&mut self, info: &RunInfo) -> Result<(), SimError> {
        let m = Metadata {
            name: RUN_METADATA.to_string(),
            metadata: info.metadata(),
        };
        self.w.write_metadata(&m).map_err(|e| self.err(e))
    }

    /// The channel `<prefix><quantity>` of messages of `kind` (its schema added once).
    pub fn channel(&mut self, prefix: &str, quantity: &str, kind: Kind) -> Result<u16, SimError> {
        let schema = match self.schemas.get(&kind) {
            Some(id) => *id,
            None => {
                let data = serde_json::to_string(&kind.schema())?;
                let id = self
                    .w
                    .add_schema(kind.name(), "jsonschema", data.as_bytes())
                    .map_err(|e| self.err(e))?;
                self.schemas.insert(kind, id);
                id
            }
        };
        let meta = BTreeMap::new();
        self.w
            .add_channel(schema, &format!("{prefix}{quantity}"), "json", &meta)
            .map_err(|e| self.err(e))
    }

    /// Writes `msg` on `channel`, logged and published at `t` \[s\] (sequence numbers count
    /// per channel).
    pub fn write(&mut self, channel: u16, t: f64, msg: &Value) -> Result<(), SimError> {
        let seq = self.seq.entry(channel).or_insert(0);
        let ns = nanos(t);
        let header = MessageHeader {
            channel_id: channel,
            sequence: *seq,
            log_time: ns,
            publish_time: ns,
        };
        *seq += 1;
        let data = serde_json::to_string(msg)?;
        if let Err(e) = self.w.write_to_known_channel(&header, data.as_bytes()) {
            return Err(self.err(e));
        }
        self.count += 1;
        Ok(())
    }

    /// One run by the convention: its metadata record, a channel per `(topic, kind)` under its
    /// prefix, the scene `lines` at t = 0 on the last topic (a `SceneUpdate`), then for each
    /// sample its time and one message per other topic, in `topics` order.
    pub fn write_run<S>(
        &mut self,
        info: &RunInfo,
        topics: &[(&str, Kind)],
        lines: &[Line],
        samples: &[S],
        messages: impl Fn(&S) -> (f64, Vec<Value>),
    ) -> Result<(), SimError> {
        self.run_metadata(info)?;
        let prefix = info.prefix();
        let mut channels = Vec::with_capacity(topics.len());
        for (topic, kind) in topics {
            channels.push(self.channel(&prefix, topic, *kind)?);
        }
        if let Some(ch) = channels.last() {
            self.write(*ch, 0.0, &scene_update(0.0, lines))?;
        }
        for s in samples {
            let (t, msgs) = messages(s);
            for (ch, msg) in channels.iter().zip(&msgs) {
                self.write(*ch, t, msg)?;
            }
        }
        Ok(())
    }

    /// Finishes the file; returns the number of messages written.
    pub fn finish(mut self) -> Result<usize, SimError> {
        if let Err(e) = self.w.finish() {
            return Err(self.err(e));
        }
        Ok(self.count)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Every numeric property of a `deflect.*` schema declares a unit.
    fn check_units(v: &Value, path: &str) {
        if let Some(props) = v.get("properties").and_then(Value::as_object) {
            for (k, p) in props {
                check_units(p, &format!("{path}.{k}"));
            }
        }
        if let Some(items) = v.get("items") {
            check_units(items, path);
        }
        let numeric = matches!(
            v.get("type").and_then(Value::as_str),
            Some("number" | "integer")
        );
        if numeric {
            let d = v.get("description").and_then(Value::as_str).unwrap_or("");
            assert!(!d.is_empty(), "{path}: no unit");
        }
    }

    #[test]
    fn schemas_are_named_by_convention_and_declare_units() {
        for k in KINDS {
            let s = k.schema();
            assert_eq!(s["type"], "object", "{}", k.name());
            if k.name().starts_with("deflect.") {
                check_units(&s, k.name());
                assert!(s["properties"]["timestamp"].is_object());
            } else {
                assert_eq!(s["title"], k.name());
            }
        }
        let m = scene_update(
            0.0,
            &[Line {
                id: "a".into(),
                points: vec![[0.0; 3], [1.0, 0.0, 0.0]],
                rgb: (0, 0, 0),
                closed: false,
            }],
        );
        let e = &m["entities"][0];
        for f in [
            "timestamp",
            "frame_id",
            "id",
            "lifetime",
            "frame_locked",
            "lines",
        ] {
            assert!(e.get(f).is_some(), "{f}");
        }
        assert_eq!(e["lines"][0]["points"].as_array().unwrap().len(), 2);
        assert_eq!(nanos(-1.0), 0);
        assert_eq!(stamp(1.5)["nsec"], 500_000_000);
    }
}
