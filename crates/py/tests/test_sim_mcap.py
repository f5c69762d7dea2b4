"""deflect-sim writes an MCAP log the official Python `mcap` reader can read back.

Runs the release binary (`cargo run --release -p deflect-sim -- run ...`): one corrected
y-line at 5 g on the OC robot with the upper head (static tests and fit included, about a
second in release), then checks the channels, schemas and message counts.
"""

import json
import pathlib
import subprocess

import pytest

import mcap.reader as mcap_reader  # installed by scripts/test-all.sh

REPO = pathlib.Path(__file__).resolve().parents[3]
TOPICS = ["/desired", "/commanded", "/actual", "/dalembert_force", "/joints"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim")
    cmd = [
        "cargo", "run", "--release", "--quiet", "-p", "deflect-sim", "--",
        "run", "--mechanism", "oc", "--head", "upper", "--motion", "y", "--g", "5",
        "--correction", "on", "--out", str(out),
    ]
    res = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stderr
    assert "corrected" in res.stdout
    return out


def read(path):
    with open(path, "rb") as f:
        reader = mcap_reader.make_reader(f)
        summary = reader.get_summary()
        msgs = [(ch.topic, sch, msg, json.loads(msg.data)) for sch, ch, msg in reader.iter_messages()]
    return summary, msgs


def test_channels_and_counts(run_dir):
    path = run_dir / "run_oc_gu_y-line_5g.mcap"
    assert path.exists()
    summary, msgs = read(path)
    topics = sorted(ch.topic for ch in summary.channels.values())
    assert topics == sorted(TOPICS)
    for ch in summary.channels.values():
        assert ch.message_encoding == "json"
        schema = summary.schemas[ch.schema_id]
        assert schema.encoding == "jsonschema"
        assert json.loads(schema.data)["type"] == "object"
    counts = {t: sum(1 for m in msgs if m[0] == t) for t in TOPICS}
    n = counts["/desired"]
    # 375 ms at 2 kHz plus the 50 ms tail.
    assert 800 < n < 900, counts
    assert all(c == n for c in counts.values()), counts
    stats = summary.statistics
    assert stats.message_count == 5 * n


def test_message_contents(run_dir):
    _, msgs = read(run_dir / "run_oc_gu_y-line_5g.mcap")
    by_topic = {}
    for topic, _, msg, data in msgs:
        by_topic.setdefault(topic, []).append((msg.log_time, data))
    for topic, items in by_topic.items():
        times = [t for t, _ in items]
        assert times == sorted(times), topic
        for _, d in items[:3]:
            assert set(d["timestamp"]) == {"sec", "nsec"}
            assert 0 <= d["timestamp"]["nsec"] < 1_000_000_000
    actual = by_topic["/actual"]
    assert all("z" in d for _, d in actual)
    # Ends near the y-line's end point (0.222132, 0.075) m.
    end = actual[-1][1]
    assert abs(end["x"] - 0.222132) < 1e-3 and abs(end["y"] - 0.075) < 1e-3
    joints = by_topic["/joints"][0][1]
    assert len(joints["command"]) == len(joints["motor"]) == len(joints["link"]) == 2
    # Peak D'Alembert force ~ m* a = 5 kg x 4.8 g (the 5 g profile peaks at 4.78 g).
    fmax = max(abs(d["y"]) for _, d in by_topic["/dalembert_force"])
    assert 180 < fmax < 260, fmax


def test_other_outputs(run_dir):
    assert (run_dir / "run_oc_gu_y-line_5g.png").stat().st_size > 10_000
    runs = json.loads((run_dir / "run_oc_gu_y-line_5g.json").read_text())
    assert len(runs) == 1 and runs[0]["corrected"] is True
    assert (run_dir / "compliance_map_oc.json").exists()
