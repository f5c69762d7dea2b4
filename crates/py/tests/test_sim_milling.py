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
