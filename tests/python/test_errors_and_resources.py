# Bad input raises with the command line's messages; memory comes back; the API is documented.
import gc
import pathlib
import pydoc
import resource

import numpy as np
import pytest

import obscura
from conftest import CORNELL, SMALL

STUB = pathlib.Path(obscura.__file__).with_name("__init__.pyi")


def test_bad_scene_files_raise_naming_the_file(tmp_path):
    with pytest.raises(obscura.InputError, match="nowhere.gltf"):
        obscura.Scene(str(tmp_path / "nowhere.gltf"))
    broken = tmp_path / "broken.gltf"
    broken.write_text('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}]}')
    with pytest.raises(obscura.InputError, match="broken.gltf"):
        obscura.render(str(broken), width=8, height=8)
    assert issubclass(obscura.InputError, ValueError) and issubclass(obscura.DeviceError, RuntimeError)


def test_bad_settings_raise_the_command_lines_messages(cornell):
    with pytest.raises(obscura.InputError, match="--spp"):
        obscura.render(cornell, spp=0)
    with pytest.raises(obscura.InputError, match="--no-such-option"):
        obscura.render(cornell, no_such_option=3)
    with pytest.raises(obscura.InputError, match="--rho"):
        obscura.render(cornell, rho="cubic")
    with pytest.raises(obscura.InputError, match="--aov fancy: unknown AOV"):
        obscura.render(cornell, aovs=["fancy"], **SMALL)
    r = obscura.render(cornell, background=(0.1, 0.2, 0.3), **SMALL)
    with pytest.raises(obscura.InputError, match="no light named 'sun'"):
        r.relight({"sun": 1.0})
    with pytest.raises(obscura.InputError, match="finite and >= 0"):
        r.relight({"background": -1.0})
    with pytest.raises(obscura.InputError, match="float or an \\(r, g, b\\) triple"):
        r.relight({"background": (1.0, 2.0)})
    with pytest.raises(obscura.InputError, match="state.json"):
        obscura.load_state(str(pathlib.Path(CORNELL).parent))
    with pytest.raises(obscura.InputError, match="photos.json"):
        obscura.recover(CORNELL, "photos.json", "out")


def rss_mib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def test_sessions_and_renders_closed_in_a_loop_give_their_memory_back(cornell):
    def cycle():
        with obscura.Session(cornell, width=16, height=12, spp=1) as s:
            s.apply({"light": "light_rectangle_1", "scale": 0.5})
            assert np.isfinite(s.result().aovs["combined"]).all()
        obscura.render(cornell, width=16, height=12, spp=1)

    for _ in range(5):  # the kernels compiled, the allocators' pools warm
        cycle()
    gc.collect()
    buffers, rss = obscura.buffer_bytes_in_use(), rss_mib()
    for _ in range(20):
        cycle()
    gc.collect()
    assert obscura.buffer_bytes_in_use() == buffers, "device memory held after 20 sessions were closed"
    # The device's buffers are counted exactly above; the host's RSS only coarsely (a leak of one
    # 16 x 12 frame per cycle, ~40 KB, would be 0.8 MiB here and 2 MiB over 50 cycles: under this
    # bound either way).
    assert rss_mib() - rss < 8.0, f"host RSS grew {rss_mib() - rss:.1f} MiB over 20 cycles"


def test_the_stub_and_the_help_cover_the_api():
    stub = STUB.read_text()
    for name in obscura.__all__:
        assert f"def {name}(" in stub or f"class {name}" in stub, f"{name} is missing from {STUB.name}"
    for cls in (obscura.Result, obscura.Session, obscura.Scene):
        for attribute in dir(cls):
            if not attribute.startswith("_"):
                assert f"def {attribute}(" in stub, f"{cls.__name__}.{attribute} is missing from {STUB.name}"
    text = pydoc.render_doc(obscura, renderer=pydoc.plaintext)
    for needle in ("render(", "relight", "Session", "light_stack", "InputError"):
        assert needle in text
