"""help() and inspect show every keyword default as its value (no `Ellipsis`), and the shown
defaults are the ones the functions use."""

import inspect

import numpy as np

import deflect


def public_callables():
    for name in dir(deflect):
        if name.startswith("_"):
            continue
        obj = getattr(deflect, name)
        if callable(obj):
            yield name, obj
        if isinstance(obj, type):
            for m in dir(obj):
                if not m.startswith("_") and callable(getattr(obj, m)):
                    yield f"{name}.{m}", getattr(obj, m)


def test_no_default_shows_as_ellipsis():
    seen = 0
    for name, obj in public_callables():
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        seen += 1
        for p in sig.parameters.values():
            assert p.default is not Ellipsis, f"{name}: {p.name} shows Ellipsis"
    assert seen > 50


def test_shown_defaults_are_the_used_ones():
    sig = inspect.signature(deflect.plan_line)
    assert sig.parameters["rate_hz"].default == 2000.0
    a = deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0)
    b = deflect.plan_line([0.0, 0.0], [0.1, 0.0], 1.0, 10.0, 100.0, rate_hz=2000.0)
    np.testing.assert_array_equal(a.t, b.t)
    assert inspect.signature(deflect.ParallelRobot2).parameters["min_sigma"].default == 0.02
    assert inspect.signature(deflect.DalembertCorrector).parameters["mass"].default == 5.0
    tracer = inspect.signature(deflect.ContourTracer).parameters
    assert tracer["max_turn"].default == np.pi / 4
    assert tracer["approach_direction"].default == (1.0, 0.0)
    assert inspect.signature(deflect.OnlineCompensator).parameters["pilot"].default == (150.0, 0.08)


def test_every_public_object_has_a_docstring():
    """help() shows something for every public class, function, method and property."""
    import inspect

    missing = []
    for name in deflect.__all__:
        obj = getattr(deflect, name)
        if name == "__version__":
            continue
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, Exception):
            for member, raw in vars(obj).items():
                if member.startswith("_"):
                    continue
                doc = getattr(obj, member).__doc__ if isinstance(raw, staticmethod) else raw.__doc__
                if not (doc or "").strip() or doc == type(raw).__doc__:
                    missing.append(f"{name}.{member}")
    assert missing == []
