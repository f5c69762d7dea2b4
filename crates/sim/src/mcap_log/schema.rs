//! The JSON schemas of the log's message kinds (`deflect.<Type>` and the Foxglove ones used),
//! SI units in every numeric field's description.

use serde_json::{Value, json};

/// A number of unit `unit`.
fn num(unit: &str) -> Value {
    json!({"type": "number", "description": unit})
}

/// The JSON schema of a `{sec, nsec}` timestamp.
fn time_schema() -> Value {
    json!({"type": "object", "title": "time", "properties": {
        "sec": {"type": "integer", "minimum": 0, "description": "s"},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999, "description": "ns"}}})
}

/// A Foxglove `Vector3` of unit `unit`.
fn vec3_schema(unit: &str) -> Value {
    json!({"type": "object", "properties": {"x": num(unit), "y": num(unit), "z": num(unit)}})
}

/// A Foxglove `Color` (components 0 to 1).
fn color_schema() -> Value {
    let c = num("1 (0 to 1)");
    json!({"type": "object", "properties": {"r": c, "g": c, "b": c, "a": c}})
}

/// A Foxglove `Pose`: position \[m\] and unit quaternion.
fn foxglove_pose_schema() -> Value {
    json!({"type": "object", "properties": {
        "position": vec3_schema("m"),
        "orientation": {"type": "object", "properties": {
            "x": num("1"), "y": num("1"), "z": num("1"), "w": num("1")}}}})
}

/// A `deflect.<Type>` schema: `timestamp`, `run` and `fields` (name, unit).
fn deflect_schema(title: &str, fields: &[(&str, Value)]) -> Value {
    let mut props = json!({
        "timestamp": time_schema(),
        "run": {"type": "string", "description": "the run's name (its topic prefix)"},
    });
    for (f, v) in fields {
        props[*f] = v.clone();
    }
    json!({"title": title, "type": "object", "properties": props})
}

/// The fields `x, y, z` of unit `u`.
fn xyz(u: &str) -> Vec<(&'static str, Value)> {
    vec![("x", num(u)), ("y", num(u)), ("z", num(u))]
}

/// The fields `fx, fy, fz` \[N\].
fn force_fields() -> Vec<(&'static str, Value)> {
    vec![("fx", num("N")), ("fy", num("N")), ("fz", num("N"))]
}

/// An array of joint angles \[rad\], `what` they are.
fn rad_array(what: &str) -> Value {
    json!({"type": "array", "items": {"type": "number", "description": "rad"},
           "description": format!("rad, {what}, one per joint")})
}

/// `deflect.Point`.
pub(super) fn point() -> Value {
    deflect_schema("point [m], base frame", &xyz("m"))
}

/// `deflect.Pose`.
pub(super) fn pose() -> Value {
    let mut f = xyz("m");
    for q in ["qx", "qy", "qz", "qw"] {
        f.push((q, num("1 (unit quaternion)")));
    }
    deflect_schema("pose, base frame", &f)
}

/// `deflect.Force`.
pub(super) fn force() -> Value {
    deflect_schema("force [N], base frame", &force_fields())
}

/// `deflect.Wrench`.
pub(super) fn wrench() -> Value {
    let mut f = force_fields();
    for m in ["mx", "my", "mz"] {
        f.push((m, num("N m")));
    }
    deflect_schema("wrench [N, N m]", &f)
}

/// `deflect.Displacement`.
pub(super) fn displacement() -> Value {
    let mut f = vec![("dx", num("m")), ("dy", num("m")), ("dz", num("m"))];
    for r in ["rx", "ry", "rz"] {
        f.push((r, num("rad (rotation vector)")));
    }
    deflect_schema("small 6-D displacement [m, rad], base frame", &f)
}

/// `deflect.JointState`.
pub(super) fn joint_state() -> Value {
    deflect_schema(
        "joint angles [rad]",
        &[
            ("command", rad_array("commanded")),
            ("motor", rad_array("motor side")),
            ("link", rad_array("link side")),
        ],
    )
}

/// `deflect.PathError`.
pub(super) fn path_error() -> Value {
    deflect_schema(
        "distance of the tool point from the desired path [m]",
        &[("distance", num("m"))],
    )
}

/// `deflect.PilotControl`.
pub(super) fn pilot_control() -> Value {
    deflect_schema(
        "pilot control of the force estimate",
        &[(
            "weight",
            num("1 (0: measured force only, 1: estimate only)"),
        )],
    )
}

/// `deflect.TracerState`.
pub(super) fn tracer_state() -> Value {
    deflect_schema(
        "state of the contour tracer",
        &[(
            "state",
            json!({"type": "string", "description": "tracer phase"}),
        )],
    )
}

/// `deflect.Engagement`.
pub(super) fn engagement() -> Value {
    deflect_schema(
        "engagement of the cutter with the material",
        &[
            ("depth", num("m (axial depth, 0 in air)")),
            (
                "entry_angle",
                num("rad (first engaged immersion angle, clockwise from +y, feed +x)"),
            ),
            ("exit_angle", num("rad (last engaged angle)")),
            (
                "arcs",
                json!({"type": "integer", "minimum": 0,
                           "description": "1 (number of engaged arcs)"}),
            ),
        ],
    )
}

/// `foxglove.PosesInFrame`.
pub(super) fn poses_in_frame() -> Value {
    json!({
        "title": "foxglove.PosesInFrame", "type": "object", "properties": {
            "timestamp": time_schema(),
            "frame_id": {"type": "string"},
            "poses": {"type": "array", "items": foxglove_pose_schema()}}})
}

/// `foxglove.SceneUpdate` (lines only; the other primitives as empty arrays).
pub(super) fn scene_update() -> Value {
    let line = json!({"type": "object", "properties": {
        "type": {"type": "integer", "description": "0 LINE_STRIP, 1 LINE_LOOP, 2 LINE_LIST"},
        "pose": foxglove_pose_schema(),
        "thickness": num("px (scale_invariant) or m"),
        "scale_invariant": {"type": "boolean"},
        "points": {"type": "array", "items": vec3_schema("m")},
        "color": color_schema(),
        "colors": {"type": "array", "items": color_schema()},
        "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}}}});
    let empty = json!({"type": "array", "items": {"type": "object"}});
    let entity = json!({"type": "object", "properties": {
        "timestamp": time_schema(),
        "frame_id": {"type": "string"},
        "id": {"type": "string"},
        "lifetime": {"type": "object", "properties": {
            "sec": {"type": "integer", "description": "s"},
            "nsec": {"type": "integer", "description": "ns"}}},
        "frame_locked": {"type": "boolean"},
        "metadata": empty, "arrows": empty, "cubes": empty, "spheres": empty,
        "cylinders": empty, "triangles": empty, "texts": empty, "models": empty,
        "lines": {"type": "array", "items": line}}});
    json!({"title": "foxglove.SceneUpdate", "type": "object", "properties": {
        "deletions": {"type": "array", "items": {"type": "object"}},
        "entities": {"type": "array", "items": entity}}})
}
