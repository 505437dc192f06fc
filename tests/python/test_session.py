# obscura.Session: the same edit session as `relight --edits` (frames and reports equal), errors
# that leave it as it was, and two sessions in one process.
import json

import numpy as np
import pytest

import obscura
from conftest import CORNELL, LIGHT_IN_BOX, SMALL, assert_same, run_cli

EDITS = [
    {"light": "light_rectangle_1", "scale": 0.5},
    {"add_light": {"type": "point", "name": "lamp", "position": [0.4, 1.5, 0.6], "intensity": 3,
                   "color": [1, 0.8, 0.6]}},
    {"move": "cube_1", "translate": [0.15, 0, 0], "rotate_deg": [0, 10, 0]},
    {"light": "lamp", "color": [0.5, 1, 1]},
    {"remove_light": "lamp"},
]


def test_an_edit_sequence_gives_relight_edits_frames_and_reports(binary, cornell, tmp_path):
    edits_file = tmp_path / "edits.json"
    edits_file.write_text(json.dumps(EDITS))
    out = tmp_path / "cli"
    run_cli(binary, "relight", CORNELL, "--edits", edits_file, "-o", out, "--width", SMALL["width"],
            "--height", SMALL["height"], "--spp", SMALL["spp"])
    cli_reports = [json.loads(line) for line in (out / "edits.jsonl").read_text().splitlines()]
    # relight --edits reserves a light slot per add_light: the same frame layout here.
    with obscura.Session(cornell, spare_lights=1, **SMALL) as s:
        frames = [s.result()]
        reports = []
        for edit in EDITS:
            reports.append(s.apply(edit))
            frames.append(s.result())
        assert s.light_names == ["light_rectangle_1"]
    for n, frame in enumerate(frames):
        layers = obscura.read_image(str(out / f"frame-{n:03}.exr"))
        for name, array in frame.aovs.items():
            assert_same(array, layers[name], f"frame {n}, aov {name}")
        for i, light in enumerate(frame.light_names):
            assert_same(frame.light_stack[i], layers["light." + light], f"frame {n}, light {light}", atol=1e-6)
    for n, (ours, theirs) in enumerate(zip(reports, cli_reports)):
        for key in ("edit", "kind", "name", "pixels_retraced", "rays"):
            assert ours[key] == theirs[key], f"edit {n}: {key}"
    assert reports[2]["kind"] == "move" and 0 < reports[2]["pixels_retraced"] < SMALL["width"] * SMALL["height"]


def test_a_bad_edit_raises_and_leaves_the_session_as_it_was(cornell):
    with obscura.Session(cornell, **SMALL) as s:
        before = s.result().aovs["combined"].copy()
        with pytest.raises(obscura.InputError, match="no light named 'nope'|'nope'"):
            s.apply({"light": "nope", "scale": 2})
        with pytest.raises(obscura.InputError, match="Session.apply: entry 0"):
            s.apply({"scale": 2})
        with pytest.raises(obscura.InputError, match="missing.gltf"):
            s.apply({"insert": "missing.gltf", "name": "x", "translate": [0, 0, 0]})
        assert_same(s.result().aovs["combined"], before, "after refused edits")
        report = s.apply({"light": "light_rectangle_1", "scale": 2.0})
        assert report["kind"] == "scale" and report["pixels_retraced"] == 0
    assert s.closed
    with pytest.raises(obscura.InputError, match="closed"):
        s.result()


def test_two_sessions_in_one_process_keep_their_own_frames(cornell):
    box = obscura.Scene(str(LIGHT_IN_BOX))
    # A session composes with the reached I_a (it edits the scene), a still render with the seen one.
    alone = obscura.render(box, ambient="reached", **SMALL).aovs["combined"].copy()
    with obscura.Session(cornell, **SMALL) as a, obscura.Session(box, **SMALL) as b:
        a.apply({"light": "light_rectangle_1", "scale": 0.25})
        b.apply({"light": "inner_light", "scale": 2.0})
        a.apply({"remove": "cube_2"})
        assert_same(b.result().aovs["combined"], 2.0 * alone, "the other session's frame", rtol=1e-5, atol=1e-6)
        assert "cube_2" not in a.object_names and "closed_box" in b.object_names


def test_renders_from_two_threads_equal_renders_one_after_the_other(cornell):
    import threading
    box = obscura.Scene(str(LIGHT_IN_BOX))
    alone = [obscura.render(s, **SMALL).aovs["combined"].copy() for s in (cornell, box)]
    results = [None, None]

    def render(i, scene):
        results[i] = obscura.render(scene, **SMALL).aovs["combined"]

    threads = [threading.Thread(target=render, args=(i, s)) for i, s in enumerate((cornell, box))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i in range(2):
        assert_same(results[i], alone[i], f"thread {i}")


def test_a_session_saves_a_state_that_relight_dir_reads(binary, cornell, tmp_path):
    with obscura.Session(cornell, **SMALL) as s:
        s.apply({"light": "light_rectangle_1", "color": [1.0, 0.5, 0.5]})
        s.save_state(str(tmp_path / "state"))
        frame = s.result()
    run_cli(binary, "relight", tmp_path / "state", "--light", "light_rectangle_1=2", "-o", tmp_path / "relit.exr")
    relit = obscura.read_image(str(tmp_path / "relit.exr"))["combined"]
    assert_same(relit, frame.relight({"light_rectangle_1": 2.0}), "relight DIR against Result.relight", atol=1e-6)
