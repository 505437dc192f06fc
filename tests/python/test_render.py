# obscura.render and Result: the arrays equal the command line's EXR, relighting equals NumPy's
# sum of the light stack, a saved state comes back, callbacks and threads behave.
import threading
import time

import numpy as np
import pytest

import obscura
from conftest import CORNELL, SMALL, assert_same, run_cli


def test_render_arrays_equal_the_command_lines_exr(binary, cornell, tmp_path):
    r = obscura.render(cornell, **SMALL)
    exr = tmp_path / "frame.exr"
    run_cli(binary, "render", CORNELL, "-o", exr, "--width", SMALL["width"], "--height", SMALL["height"],
            "--spp", SMALL["spp"])
    layers = obscura.read_image(str(exr))
    assert "combined" in r.aovs
    # Every AOV the EXR holds, the same device and kernels: equal to the bit.
    for name, array in r.aovs.items():
        assert array.dtype == np.float32 and array.shape[:2] == (SMALL["height"], SMALL["width"])
        assert_same(array, layers[name], f"aov {name}")
    # The EXR's light layers are the light stack.
    assert r.light_names == [n for n in (k[len("light."):] for k in layers if k.startswith("light."))]
    for i, name in enumerate(r.light_names):
        assert_same(r.light_stack[i], layers["light." + name], f"light {name}", atol=1e-6)
    assert np.all(np.isfinite(r.aovs["combined"])) and r.aovs["combined"].max() > 0.0


def test_relight_equals_the_numpy_sum_of_the_light_stack(cornell):
    r = obscura.render(cornell, background=(0.05, 0.1, 0.2), **SMALL)  # the sky: a second light
    assert r.light_names == ["light_rectangle_1", "background"]
    stack = r.light_stack
    assert stack.shape == (len(r.light_names), SMALL["height"], SMALL["width"], 3)
    # Unscaled, the layers sum to the GPU's combined (the C++ compose against compose.comp).
    assert_same(stack.sum(axis=0), r.aovs["combined"], "sum of layers", rtol=1e-5, atol=1e-6)
    assert_same(r.relight({}), r.aovs["combined"], "relight({})", rtol=1e-5, atol=1e-6)
    scales = {name: (0.5 + i, 1.0, 0.25 * (i + 1)) for i, name in enumerate(r.light_names)}
    scales[r.light_names[0]] = 3.0
    factors = np.array([np.broadcast_to(np.asarray(scales[n], np.float32), (3,)) for n in r.light_names])
    expected = np.einsum("lhwc,lc->hwc", stack, factors)
    assert_same(r.relight(scales), expected, "relight against NumPy", rtol=1e-5, atol=1e-6)
    # A light switched off takes its whole share, its indirect light included.
    off = r.relight({r.light_names[0]: 0.0})
    assert_same(off, stack[1:].sum(axis=0), "light off", rtol=1e-5, atol=1e-6)


def test_saved_state_loads_back_and_relights_the_same(cornell, tmp_path):
    r = obscura.render(cornell, **SMALL)
    r.save_state(str(tmp_path / "state"))
    loaded = obscura.load_state(str(tmp_path / "state"))
    assert loaded.light_names == r.light_names
    scales = {r.light_names[0]: (2.0, 0.5, 1.0)}
    assert_same(loaded.relight(scales), r.relight(scales), "relit after a round trip", atol=1e-6)
    assert loaded.display is None and r.display.shape == (SMALL["height"], SMALL["width"], 4)


def test_arrays_are_views_that_outlive_the_result_and_export_through_dlpack(cornell):
    r = obscura.render(cornell, **SMALL)
    combined, stack = r.aovs["combined"], r.light_stack
    del r  # the arrays keep the frame's memory alive
    assert combined.base is not None and np.isfinite(combined).all()
    assert np.shares_memory(np.from_dlpack(combined), combined)
    assert memoryview(stack).shape == stack.shape and memoryview(combined).format == "f"


def test_progress_is_reported_and_its_exception_stops_the_render(cornell):
    seen = []
    obscura.render(cornell, progress=lambda done, total, s: seen.append((done, total)), **SMALL)
    assert seen and seen[-1] == (SMALL["spp"], SMALL["spp"])

    def stop(done, total, seconds):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        obscura.render(cornell, progress=stop, **SMALL)
    assert np.isfinite(obscura.render(cornell, **SMALL).aovs["combined"]).all()  # the module still renders


def test_the_gil_is_released_while_the_device_renders(cornell):
    ticks = 0
    running = True

    def count():
        nonlocal ticks
        while running:
            ticks += 1
            time.sleep(0.001)

    thread = threading.Thread(target=count)
    thread.start()
    start = ticks
    obscura.render(cornell, width=64, height=48, spp=8)
    during = ticks - start
    running = False
    thread.join()
    assert during > 5, "another Python thread did not run while the frame rendered"


def test_path_tracing_returns_combined_and_no_light_stack(cornell):
    r = obscura.render(cornell, method="pathtrace", width=16, height=12, spp=2)
    assert list(r.aovs) == ["combined"] and r.light_names == []
    with pytest.raises(obscura.InputError, match="per-light transport"):
        r.relight({})


def test_a_scene_lists_what_edits_and_relighting_can_name(cornell):
    info = obscura.info(str(CORNELL))
    assert [light["name"] for light in info["lights"]] == cornell.light_names == ["light_rectangle_1"]
    assert info["lights"][0]["type"] == "area" and info["lights"][0]["triangles"] == 2
    assert len(cornell.objects) == 8 and cornell.objects[5]["name"] == "cube_1"
    lo, hi = cornell.bounds
    assert np.allclose(lo, (-1, 0, -1), atol=1e-6) and np.allclose(hi, (1, 2, 1), atol=1e-6)
    assert cornell.cameras[0]["name"] == "mitsuba_sensor" and cornell.triangles == 36
    with pytest.raises(obscura.InputError, match="light_groups='material'"):
        obscura.render(cornell, light_groups="material")
