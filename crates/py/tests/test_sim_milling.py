"""deflect-sim milling writes an MCAP log the Python `mcap` reader can read back.

Runs the release binary (`cargo run --release -p deflect-sim -- milling --program groove --cut 0.4`, the KR 300
in rapier: about 10-20 s on 2 cores, most of it the identification's static tests) and checks channels, schemas, message counts and what the runs show:
compensation reduces the path error, pilot control more so.
"""

import json
import pathlib
import subprocess

import pytest

import mcap.reader as mcap_reader  # installed by scripts/test-all.sh

REPO = pathlib.Path(__file__).resolve().parents[3]
RUNS = ["uncompensated", "cartesian", "pilot", "uncalibrated"]
# Every topic is logged every control cycle but `paths` (one foxglove.SceneUpdate at t = 0).
TOPICS = ["nominal", "actual", "commanded", "force_measured", "force_filtered", "process_force",
          "correction", "error", "pilot", "tcp_pose", "paths"]


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("milling")
    cmd = [
        "cargo", "run", "--release", "--quiet", "-p", "deflect-sim", "--",
        "milling", "--program", "groove", "--cut", "0.4", "--out", str(out),
    ]
    res = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stderr
    assert "path error" in res.stdout
    return out


def read(path):
    with open(path, "rb") as f:
        reader = mcap_reader.make_reader(f)
        summary = reader.get_summary()
        msgs = [(ch.topic, msg, json.loads(msg.data)) for _, ch, msg in reader.iter_messages()]
    return summary, msgs


def test_channels_and_counts(out_dir):
    summary, msgs = read(out_dir / "milling.mcap")
    want = sorted(f"/milling/{r}/{t}" for r in RUNS for t in TOPICS)
    assert sorted(ch.topic for ch in summary.channels.values()) == want
    for ch in summary.channels.values():
        assert ch.message_encoding == "json"
        schema = summary.schemas[ch.schema_id]
        assert schema.encoding == "jsonschema"
        assert json.loads(schema.data)["type"] == "object"
    counts = {}
    for topic, _, _ in msgs:
        counts[topic] = counts.get(topic, 0) + 1
    n = counts["/milling/pilot/actual"]
    # 0.1 + 0.2 + 0.3 + 0.4 + 0.4 s at 4 ms.
    assert 340 < n < 360, counts
    assert all(c == (1 if t.endswith("/paths") else n) for t, c in counts.items()), counts
    assert summary.statistics.message_count == len(RUNS) * ((len(TOPICS) - 1) * n + 1)


def test_runs(out_dir):
    _, msgs = read(out_dir / "milling.mcap")
    err = {r: [] for r in RUNS}
    for topic, msg, d in msgs:
        run, name = topic.split("/")[2:4]
        if name == "error":
            # deflect.PathError: the distance in metres.
            err[run].append((msg.log_time, d["distance"] * 1e3))
        if name in ("force_measured", "force_filtered"):
            assert set(d) >= {"timestamp", "run", "fx", "fy", "fz", "mx", "my", "mz"}
    peak = {r: max(e for _, e in v) for r, v in err.items()}
    assert 0.7 < peak["uncompensated"] < 1.5, peak
    assert peak["pilot"] < peak["cartesian"] < peak["uncompensated"], peak
    times = [t for t, _ in err["pilot"]]
    assert times == sorted(times)


def test_other_outputs(out_dir):
    s = json.loads((out_dir / "milling_summary.json").read_text())
    assert [r["run"] for r in s["runs"]] == RUNS
    # 30 axes of the KR 300's ten finite virtual joints, from frame pairs with 2 urad noise:
    # each within 4 standard errors and 5 % of the stiffness file's value.
    assert len(s["stiffness"]) == 30
    for e in s["stiffness"]:
        err = abs(e["k_frames"] - e["k_true"])
        assert err < 4 * e["se_frames"] and err < 0.05 * e["k_true"], e
    assert abs(s["sensor"]["weight"][1] / s["sensor"]["weight"][0] - 1) < 0.01
    for name in ["milling_error.png", "milling_stiffness.png"]:
        assert (out_dir / name).stat().st_size > 10_000
    assert (out_dir / "milling_summary.csv").read_text().startswith("run,max_mm")


# A user's arm and tool: the UR5 of example-robot-data with deflect's assumed stiffness file,
# a 1 mm slot with a 6 mm two-flute mill through a 30 mm block (about 6 s in release).
SLOT = """(1 mm slot, 6 mm two-flute mill)
G21 G90
G0 X-8 Y10 Z5
S18000 M3
G1 Z-1 F600
X38
G0 Z5
M30
"""


@pytest.fixture(scope="module")
def ur5_out(tmp_path_factory):
    from conftest import ur5_urdf

    out = tmp_path_factory.mktemp("milling_ur5")
    program = out / "slot.nc"
    program.write_text(SLOT)
    cmd = [
        "cargo", "run", "--release", "--quiet", "-p", "deflect-sim", "--", "milling",
        "--urdf", str(ur5_urdf()), "--stiffness", str(REPO / "robots/ur5/ur5_stiffness.toml"),
        "--tip", "tool0", "--placement", "0.55,0.10,0.17,0,0,0",
        "--q0=0,-1.2,1.8,-2.17,-1.57,0", "--program", str(program), "--stock", "0,0,30,20",
        "--diameter", "6", "--flutes", "2", "--out", str(out),
    ]
    res = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stderr
    return out


def test_a_users_arm_tool_and_program(ur5_out):
    s = json.loads((ur5_out / "milling_summary.json").read_text())
    assert s["robot"] == "ur5"
    m = {r["mode"]: r["metrics"] for r in s["runs"]}
    assert list(m) == [
        "uncompensated", "offline", "cartesian", "hybrid", "axis_specific", "combined"
    ]
    # One cut from the block's edge at x = 0 to its end at x = 30 mm.
    assert len(s["cuts"]) == 1
    cut = s["cuts"][0]
    # The phase is the radius over the feed. In the material from the centre at -4.25 mm
    # (the front probe, two 0.5 mm cells outside the 3 mm cutter, meets the block's edge,
    # which the z-map ramps over the half cell from x = -0.25 mm) until the side probes,
    # sqrt(4^2 - 3^2) = 2.646 mm ahead of the tip, leave the block's end (ramped to
    # 30.25 mm): tip at 27.604 mm; 31.854 mm at 10 mm/s.
    assert cut["phase"] == pytest.approx(0.003 / 0.010, rel=1e-9)
    assert cut["exit"] - cut["entry"] == pytest.approx(3.1854, abs=0.01)
    # The UR5 bends by tenths of a millimetre under the slot's tens of newtons; the offline
    # compensation takes nearly all of it, the online loops most of it.
    assert m["uncompensated"]["max_mm"] > 0.2
    assert m["offline"]["max_mm"] < 0.1 * m["uncompensated"]["max_mm"]
    for mode in ("cartesian", "hybrid", "axis_specific"):
        assert m[mode]["rms_mm"] < 0.5 * m["uncompensated"]["rms_mm"], (mode, m)


def test_the_engagement_is_logged(ur5_out):
    _, msgs = read(ur5_out / "milling.mcap")
    eng = [d for topic, _, d in msgs if topic == "/milling/offline/engagement"]
    assert eng and set(eng[0]) == {"timestamp", "run", "depth", "entry_angle", "exit_angle", "arcs"}
    cutting = [d for d in eng if d["arcs"] > 0]
    # Mid-slot: the full front half engaged (0..pi) at the programmed 1 mm depth.
    mid = cutting[len(cutting) // 2]
    assert mid["depth"] == pytest.approx(1e-3, abs=2e-5)
    assert mid["entry_angle"] == pytest.approx(0.0, abs=0.05)
    assert mid["exit_angle"] == pytest.approx(3.14159, abs=0.05)
    assert all(d["depth"] == 0 and d["arcs"] == 0 for d in eng[:10])
