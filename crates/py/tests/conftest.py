"""Shared fixtures: paths of the shipped robots and an independent numpy VJM reference."""

import math
import pathlib
import tomllib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
KR300_URDF = REPO / "robots" / "kr300" / "kr300_r2500.urdf"
KR300_TOML = REPO / "robots" / "kr300" / "kr300_r2500_stiffness.toml"
KR300_POSE = np.array([0.0, -0.9, 1.4, 0.0, 1.0708, 0.0])


def rpy_matrix(r, p, y):
    """URDF roll-pitch-yaw: Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = map(float, (math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def homogeneous(rot=np.eye(3), xyz=(0.0, 0.0, 0.0)):
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = xyz
    return t


def axis_angle(axis, angle):
    """Rodrigues' formula."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


class NumpyChain:
    """An independent reading of a URDF chain + stiffness TOML and of Eq. 1-9 of the VJM paper,
    written from the paper with xml.etree and numpy only."""

    def __init__(self, urdf_path, toml_path, tip):
        root = ET.parse(urdf_path).getroot()
        joints = {j.find("child").get("link"): j for j in root.findall("joint")}
        path = []
        link = tip
        while link in joints:
            j = joints[link]
            path.append(j)
            link = j.find("parent").get("link")
        path.reverse()
        springs = tomllib.loads(pathlib.Path(toml_path).read_text())["virtual_joint"] if toml_path else []
        # Elements: ("fixed", T) | ("joint", kind, axis) | ("spring", compliance 3-vector)
        self.elements = []

        by_name = {j.get("name"): j for j in root.findall("joint")}

        def placement(s):
            """(link, offset) of a spring: `link` + xyz/rpy, or `joint`: the joint's child
            link frame turned so that its x axis is the joint axis (shortest rotation)."""
            if "link" in s:
                return s["link"], homogeneous(rpy_matrix(*s.get("rpy", [0, 0, 0])), s.get("xyz", [0, 0, 0]))
            j = by_name[s["joint"]]
            axis = np.array([float(v) for v in j.find("axis").get("xyz").split()])
            axis /= np.linalg.norm(axis)
            x = np.array([1.0, 0.0, 0.0])
            c = float(x @ axis)
            if c < -1 + 1e-12:
                rot = axis_angle([0, 0, 1], math.pi)
            elif c > 1 - 1e-12:
                rot = np.eye(3)
            else:
                rot = axis_angle(np.cross(x, axis), math.acos(c))
            return j.find("child").get("link"), homogeneous(rot)

        def add_springs(link_name):
            for s in springs:
                on, off = placement(s)
                if on != link_name:
                    continue
                self.elements.append(("fixed", off))
                self.elements.append(("spring", np.array([1.0 / k for k in s["k"]])))
                self.elements.append(("fixed", np.linalg.inv(off)))

        add_springs(link)
        self.dof = 0
        for j in path:
            o = j.find("origin")
            xyz = [float(v) for v in o.get("xyz", "0 0 0").split()] if o is not None else [0, 0, 0]
            rpy = [float(v) for v in o.get("rpy", "0 0 0").split()] if o is not None else [0, 0, 0]
            self.elements.append(("fixed", homogeneous(rpy_matrix(*rpy), xyz)))
            kind = j.get("type")
            if kind in ("revolute", "continuous", "prismatic"):
                ax = j.find("axis")
                axis = [float(v) for v in ax.get("xyz").split()] if ax is not None else [1, 0, 0]
                self.elements.append(("joint", kind, np.array(axis)))
                self.dof += 1
            add_springs(j.find("child").get("link"))

    def _walk(self, q, angles=None):
        """Yields (element, pose before it) and returns the final pose."""
        t = np.eye(4)
        qi = 0
        si = 0
        frames = []
        for e in self.elements:
            frames.append((e, t.copy()))
            if e[0] == "fixed":
                t = t @ e[1]
            elif e[0] == "joint":
                if e[1] == "prismatic":
                    t = t @ homogeneous(np.eye(3), e[2] / np.linalg.norm(e[2]) * q[qi])
                else:
                    t = t @ homogeneous(axis_angle(e[2], q[qi]))
                qi += 1
            elif angles is not None:
                a, b, g = angles[si]
                # Eq. 4: R* = Rz(gamma) Ry(beta) Rx(alpha)
                t = t @ homogeneous(rpy_matrix(a, b, g))
                si += 1
        return t, frames

    def forward(self, q):
        return self._walk(q)[0]

    def deflection(self, q, wrench):
        tcp, frames = self._walk(q)
        f, m = np.asarray(wrench[:3], float), np.asarray(wrench[3:], float)
        angles = []
        for e, t in frames:
            if e[0] != "spring":
                continue
            r = tcp[:3, 3] - t[:3, 3]  # Eq. 6 lever, base frame
            local = t[:3, :3].T @ (m + np.cross(r, f))  # Eq. 5
            angles.append(e[1] * local)  # Eq. 7
        d, _ = self._walk(q, angles)  # Eq. 8
        dp = d[:3, 3] - tcp[:3, 3]  # Eq. 9
        rel = d[:3, :3] @ tcp[:3, :3].T
        angle = math.acos(max(-1.0, min(1.0, (np.trace(rel) - 1) / 2)))
        if angle < 1e-300:
            rv = np.zeros(3)
        else:
            rv = angle / (2 * math.sin(angle)) * np.array(
                [rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]]
            )
        return np.concatenate([dp, rv])


    def equilibrium(self, q, wrench, h=1e-5):
        """Static equilibrium by the principle of virtual work, independently of deflect: the
        spring angles theta solve theta = C (Q(theta)), Q_i = F . dp/dtheta_i + M . w_i, with
        dp/dtheta_i and the angular velocity w_i = vee(dR/dtheta_i R^T) of the TCP by central
        differences of this class's own deflected forward kinematics, solved by
        scipy.optimize.root. Returns the deflection laid out as `deflection`."""
        from scipy.optimize import root

        f, m = np.asarray(wrench[:3], float), np.asarray(wrench[3:], float)
        comp = np.concatenate([e[1] for e in self.elements if e[0] == "spring"])
        n = comp.size

        def tcp(x):
            return self._walk(q, x.reshape(-1, 3))[0]

        def residual(x):
            g = np.empty(n)
            base = tcp(x)
            for i in range(n):
                e = np.zeros(n)
                e[i] = h
                tp, tm = tcp(x + e), tcp(x - e)
                dp = (tp[:3, 3] - tm[:3, 3]) / (2 * h)
                dr = (tp[:3, :3] - tm[:3, :3]) / (2 * h) @ base[:3, :3].T
                w = 0.5 * np.array([dr[2, 1] - dr[1, 2], dr[0, 2] - dr[2, 0], dr[1, 0] - dr[0, 1]])
                g[i] = f @ dp + m @ w
            return x - comp * g

        sol = root(residual, np.zeros(n), method="hybr", options={"xtol": 1e-14})
        # hybr may report slow progress at the rounding floor: judge the residual itself.
        assert np.abs(residual(sol.x)).max() < 1e-12, (sol.message, np.abs(residual(sol.x)).max())
        rigid = self.forward(q)
        d = tcp(sol.x)
        rel = d[:3, :3] @ rigid[:3, :3].T
        angle = math.acos(max(-1.0, min(1.0, (np.trace(rel) - 1) / 2)))
        rv = np.zeros(3)
        if angle > 1e-300:
            rv = angle / (2 * math.sin(angle)) * np.array(
                [rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]]
            )
        return np.concatenate([d[:3, 3] - rigid[:3, 3], rv])


@pytest.fixture(scope="session")
def kr300():
    import deflect

    return deflect.SerialRobot.from_urdf(KR300_URDF, KR300_TOML, "tcp")


@pytest.fixture(scope="session")
def kr300_ref():
    return NumpyChain(KR300_URDF, KR300_TOML, "tcp")


def ur5_urdf():
    """The UR5 URDF installed by the example-robot-data package (a test dependency)."""
    from importlib import metadata

    dist = metadata.distribution("example-robot-data")
    p = pathlib.Path(
        dist.locate_file("cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
    )
    assert p.exists(), f"example-robot-data is installed but {p} is missing"
    return p
