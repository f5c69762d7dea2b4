"""Every MCAP log deflect-sim writes follows one convention (crates/sim/README.md, "MCAP logs").

Runs the release binary (`cargo run --release -p deflect-sim -- ...`) for every scenario with
small, fast settings, all at once (about 30 s on 2 cores, most of it the KR 300 scenes), and
reads each log back with the official `mcap` reader:

* schema names are `deflect.<Type>` or `foxglove.<Type>`; a name means the same fields in
  every log; every numeric field of a `deflect.*` schema declares its unit;
* topics are `/<scenario>/<run>/<quantity>`; log times are monotone per channel, every run
  starts at t = 0 and each message's `timestamp` is its log time;
* one `deflect.run` metadata record per run with the documented keys;
* the Foxglove messages (`foxglove.PosesInFrame`, `foxglove.SceneUpdate`) have the fields
  Foxglove's 3D panel needs;
* the figures of a run are in SI (metres, newtons), and the CSV headers carry units.
"""

import json
import math
import pathlib
import re
import subprocess

import pytest

import mcap.reader as mcap_reader  # installed by scripts/test-all.sh

REPO = pathlib.Path(__file__).resolve().parents[3]

# Scenario -> (arguments, MCAP file). Small and fast: reproduce at 5 g only, the milling
# scene with a short cut and one identification pose, the serial scene on short motions.
SCENARIOS = {
    "reproduce": (["reproduce", "--g", "5"], "reproduce.mcap"),
    "run": (
        ["run", "--mechanism", "oc", "--head", "upper", "--motion", "y", "--g", "5",
         "--correction", "both"],
        "run_oc_gu_y-line_5g.mcap",
    ),
    "milling": (["milling", "--program", "groove", "--cut", "0.2", "--id-poses", "1"], "milling.mcap"),
    "contour": (["contour", "--step-mm", "3"], "contour.mcap"),
    "serial": (["serial", "--scale", "0.2", "--ramp", "0.05"], "serial.mcap"),
}

METADATA_KEYS = {
    "scenario", "run", "topic_prefix", "robot", "motion", "acceleration", "correction",
    "deflect_version", "command_line", "time_base", "units", "options",
}
FOXGLOVE = {"foxglove.PosesInFrame", "foxglove.SceneUpdate"}
# A unit in a field's name, for numeric fields without a description.
UNIT_SUFFIX = re.compile(r"_(m|mm|mm2|s|ms|n|rad|mrad|kg|g|deg|m_s|n_m)$", re.IGNORECASE)
# A description that states a unit: it opens with one (SI, "1" for dimensionless, "px" for
# the viewer's pixels), then at most a remark in parentheses or after a comma; or, for an
# integer code, it lists the codes ("0 LINE_STRIP, 1 LINE_LOOP, ...").
UNIT_DESCRIPTION = re.compile(
    r"^(m|mm|N|N m|rad|mrad|s|ms|ns|kg|1|px|m/s|m/s\^2|rad/s|rad/s\^2|Hz)(\b|$)( \([^)]*\)|, [^,]+(, [^,]+)*)?( or m)?$"
)
CODE_LIST = re.compile(r"^0 \w+(, \d+ \w+)+$")


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """Runs every scenario (concurrently) and reads its log: scenario -> Log."""
    build = subprocess.run(
        ["cargo", "build", "--release", "--quiet", "-p", "deflect-sim"],
        cwd=REPO, capture_output=True, text=True, timeout=1800,
    )
    assert build.returncode == 0, build.stderr
    meta = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=REPO, capture_output=True, text=True, timeout=600, check=True,
    )
    binary = pathlib.Path(json.loads(meta.stdout)["target_directory"]) / "release" / "deflect-sim"
    procs = {}
    for name, (args, _) in SCENARIOS.items():
        out = tmp_path_factory.mktemp(name)
        # The binary `cargo run --release -p deflect-sim` runs, built once above.
        cmd = [str(binary), *args, "--out", str(out)]
        procs[name] = (out, subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE,
                                             stderr=subprocess.PIPE, text=True))
    result = {}
    for name, (out, p) in procs.items():
        stdout, stderr = p.communicate(timeout=1800)
        assert p.returncode == 0, f"{name}: {stderr}"
        result[name] = Log(out, out / SCENARIOS[name][1], stdout)
    return result


class Log:
    """An MCAP file read back: summary, metadata records and every message (decoded)."""

    def __init__(self, out, path, stdout):
        self.out = out
        self.stdout = stdout
        with open(path, "rb") as f:
            reader = mcap_reader.make_reader(f)
            self.summary = reader.get_summary()
            self.metadata = list(reader.iter_metadata())
            self.messages = [(sch.name, ch.topic, msg.log_time, json.loads(msg.data))
                             for sch, ch, msg in reader.iter_messages()]

    def schemas(self):
        return {s.name: json.loads(s.data) for s in self.summary.schemas.values()}

    def topic(self, topic):
        return [(t, d) for _, tp, t, d in self.messages if tp == topic]


def props(schema):
    return schema.get("properties", {})


def test_every_schema_is_deflect_or_foxglove_and_json(logs):
    for name, log in logs.items():
        for ch in log.summary.channels.values():
            assert ch.message_encoding == "json", (name, ch.topic)
            schema = log.summary.schemas[ch.schema_id]
            assert schema.encoding == "jsonschema", (name, ch.topic)
            assert json.loads(schema.data)["type"] == "object"
            assert re.fullmatch(r"deflect\.[A-Z][A-Za-z]+", schema.name) or \
                schema.name in FOXGLOVE, (name, schema.name)
            # /<scenario>/<run>/<quantity>
            parts = ch.topic.split("/")
            assert len(parts) == 4 and parts[0] == "" and parts[1] == name, ch.topic


def test_a_schema_name_means_the_same_fields_everywhere(logs):
    seen = {}
    for name, log in logs.items():
        for sname, schema in log.schemas().items():
            fields = set(props(schema))
            if sname in seen:
                assert seen[sname][1] == fields, (sname, seen[sname][0], name)
            else:
                seen[sname] = (name, fields)
    # The same quantity has the same schema in every scenario.
    assert {"deflect.Point", "deflect.Force", "foxglove.PosesInFrame",
            "foxglove.SceneUpdate"} <= set(seen)
    assert seen["deflect.Point"][1] == {"timestamp", "run", "x", "y", "z"}
    # Messages carry exactly their schema's fields.
    for name, log in logs.items():
        fields = {s: set(props(v)) for s, v in log.schemas().items()}
        checked = set()
        for sname, topic, _, d in log.messages:
            if topic in checked:
                continue
            checked.add(topic)
            assert set(d) == fields[sname], (name, topic, set(d) ^ fields[sname])


def numeric_fields(schema, path=""):
    """(path, name, property) of every numeric property, nested ones included."""
    for key, p in props(schema).items():
        here = f"{path}.{key}"
        if p.get("type") in ("number", "integer"):
            yield here, key, p
        elif p.get("type") == "array" and p.get("items", {}).get("type") == "number":
            yield here, key, p
        yield from numeric_fields(p, here)
        if isinstance(p.get("items"), dict):
            yield from numeric_fields(p["items"], here + "[]")


def test_every_numeric_field_declares_its_unit(logs):
    for name, log in logs.items():
        for sname, schema in log.schemas().items():
            if not sname.startswith("deflect."):
                continue
            for path, key, p in numeric_fields(schema):
                d = p.get("description")
                if d is None:
                    assert UNIT_SUFFIX.search(key), (name, sname, path)
                elif p.get("type") == "integer" and CODE_LIST.match(d):
                    continue
                else:
                    assert UNIT_DESCRIPTION.match(d), (name, sname, path, d)


def test_one_time_base_every_run_from_zero(logs):
    for name, log in logs.items():
        last, first_of_run = {}, {}
        for _, topic, t, d in log.messages:
            assert t >= last.get(topic, 0), (name, topic)
            last[topic] = t
            # foxglove.SceneUpdate: the entities' timestamps.
            ts = d["timestamp"] if "timestamp" in d else d["entities"][0]["timestamp"]
            assert 0 <= ts["nsec"] < 1_000_000_000
            assert ts["sec"] * 1_000_000_000 + ts["nsec"] == t, (name, topic)
            run = topic.rsplit("/", 1)[0]
            first_of_run[run] = min(first_of_run.get(run, t), t)
        assert first_of_run and all(v == 0 for v in first_of_run.values()), (name, first_of_run)
        # Every run's samples start at 0, not only its scene: the TCP pose, logged every
        # sample, starts there.
        for run in first_of_run:
            assert log.topic(run + "/tcp_pose")[0][0] == 0, (name, run)


def test_run_metadata_records(logs):
    for name, log in logs.items():
        runs = {"/".join(ch.topic.split("/")[:3]) + "/" for ch in log.summary.channels.values()}
        records = [m for m in log.metadata if m.name == "deflect.run"]
        assert len(records) == len(runs), name
        assert {m.metadata["topic_prefix"] for m in records} == runs
        for m in records:
            assert set(m.metadata) == METADATA_KEYS, (name, set(m.metadata) ^ METADATA_KEYS)
            md = m.metadata
            assert md["scenario"] == name
            assert md["topic_prefix"] == f"/{name}/{md['run']}/"
            assert md["deflect_version"] and md["robot"] and md["motion"]
            assert md["acceleration"] and md["correction"]
            assert name in md["command_line"]
            assert "t = 0" in md["time_base"] and "SI" in md["units"]
            assert isinstance(json.loads(md["options"]), dict)


def check_pose(p):
    assert set(p["position"]) == {"x", "y", "z"}
    q = p["orientation"]
    assert set(q) == {"x", "y", "z", "w"}
    assert abs(math.sqrt(sum(v * v for v in q.values())) - 1) < 1e-6


def test_foxglove_messages_have_the_required_fields(logs):
    for name, log in logs.items():
        scenes = poses = 0
        for sname, topic, t, d in log.messages:
            if sname == "foxglove.PosesInFrame":
                poses += 1
                assert set(d) == {"timestamp", "frame_id", "poses"}
                assert d["frame_id"] == "base" and len(d["poses"]) == 1
                check_pose(d["poses"][0])
            elif sname == "foxglove.SceneUpdate":
                scenes += 1
                assert t == 0 and d["deletions"] == []
                assert len(d["entities"]) >= 2
                for e in d["entities"]:
                    for f in ["timestamp", "frame_id", "id", "lifetime", "frame_locked",
                              "metadata", "arrows", "cubes", "spheres", "cylinders", "lines",
                              "triangles", "texts", "models"]:
                        assert f in e, (name, f)
                    assert e["frame_id"] == "base" and e["lifetime"] == {"sec": 0, "nsec": 0}
                    for line in e["lines"]:
                        assert set(line) >= {"type", "pose", "thickness", "scale_invariant",
                                             "points", "color", "colors", "indices"}
                        assert line["type"] in (0, 1, 2)
                        check_pose(line["pose"])
                        assert len(line["points"]) >= 2
                        assert set(line["points"][0]) == {"x", "y", "z"}
                        assert set(line["color"]) == {"r", "g", "b", "a"}
        runs = len([m for m in log.metadata if m.name == "deflect.run"])
        assert scenes == runs and poses > 100 * runs, (name, scenes, poses)


def test_run_log_contents_in_si(logs):
    log = logs["run"]
    assert "corrected" in log.stdout
    prefix = "/run/oc_gu_y-line_5g_corr/"
    actual = log.topic(prefix + "actual")
    # 375 ms at 2 kHz plus the 50 ms tail, on every channel of the run but the scene.
    assert 800 < len(actual) < 900
    for q in ["desired", "commanded", "dalembert_force", "joints", "tcp_pose"]:
        assert len(log.topic(prefix + q)) == len(actual), q
    # Ends near the y-line's end point (0.222132, 0.075) m.
    end = actual[-1][1]
    assert abs(end["x"] - 0.222132) < 1e-3 and abs(end["y"] - 0.075) < 1e-3
    joints = log.topic(prefix + "joints")[0][1]
    assert len(joints["command"]) == len(joints["motor"]) == len(joints["link"]) == 2
    # Peak D'Alembert force ~ m* a = 5 kg x 4.8 g (the 5 g profile peaks at 4.78 g).
    fmax = max(abs(d["fy"]) for _, d in log.topic(prefix + "dalembert_force"))
    assert 180 < fmax < 260, fmax


def test_milling_path_error_is_in_metres(logs):
    log = logs["milling"]
    peak = {r: max(d["distance"] for _, d in log.topic(f"/milling/{r}/error"))
            for r in ["uncompensated", "cartesian", "pilot", "uncalibrated"]}
    # About a millimetre uncompensated: 1e-3 m, not 1 (mm).
    assert 3e-4 < peak["uncompensated"] < 3e-3, peak
    assert peak["cartesian"] < peak["uncompensated"], peak


def test_csv_headers_carry_units(logs):
    out = logs["reproduce"].out
    header = (out / "static_tests_oc.csv").read_text().splitlines()[0]
    assert header == "x_mm,y_mm,force_axis,force_N,dx_mm,dy_mm"
    row = (out / "static_tests_oc.csv").read_text().splitlines()[1].split(",")
    assert all(len(v) < 16 for v in row), row  # no float noise such as -75.00000000000001
    held = json.loads((out / "held_out_oc.json").read_text())
    assert all(k.endswith("_m") for k in held), held
    for csv in ["summary.csv", "mass_sweep.csv"]:
        cols = (out / csv).read_text().splitlines()[0].split(",")
        numeric = [c for c in cols if c not in ("config", "motion", "corrected")]
        assert all(UNIT_SUFFIX.search(c) for c in numeric), (csv, cols)


def test_every_scenario_writes_its_plots(logs):
    pngs = {
        "reproduce": ["paths_y-line_5g.png", "error_vs_g_y-line.png"],
        "run": ["run_oc_gu_y-line_5g.png"],
        "milling": ["milling_error.png", "milling_stiffness.png"],
        "contour": ["contour_circle.png"],
        "serial": ["serial.png"],
    }
    for name, files in pngs.items():
        for f in files:
            assert (logs[name].out / f).stat().st_size > 10_000, (name, f)
