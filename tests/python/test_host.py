"""The module as a host's long-running process uses it: threads, memory, clean-up."""

from __future__ import annotations

import threading
import time

import snell
from conftest import SPHERE, lens_arrays


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_two_hundred_renders_leave_host_memory_flat():
    # Without the validation layer, whose own bookkeeping grows with every submission.
    with snell.Device(validation=False) as device:
        renderer = snell.Renderer(device, lens_arrays())
        view = snell.View(64, 48, camera=0)
        positions = renderer.positions(1).copy()
        for frame in range(40):  # warm up: pipelines, pools, the allocator's arenas
            renderer.set_vertices(1, positions * (1.0 + 0.001 * (frame % 7)))
            renderer.render(view)
        before = resident_bytes()
        for frame in range(200):
            renderer.set_vertices(1, positions * (1.0 + 0.001 * (frame % 7)))
            renderer.render(view)
        grown = resident_bytes() - before
    assert grown < 4 << 20, f"host memory grew {grown / 2**20:.1f} MiB over 200 renders"


def test_python_threads_run_while_the_gpu_renders(device):
    renderer = snell.Renderer(device, lens_arrays())
    view = snell.View(320, 240, camera=0)
    renderer.render(view)  # pipelines compiled, trees built
    view.fresnel = not view.fresnel  # so the next frame traces again
    ticks, stop = [0], threading.Event()

    def count() -> None:
        while not stop.is_set():
            ticks[0] += 1

    counter = threading.Thread(target=count)
    counter.start()
    time.sleep(0.05)
    before = ticks[0]
    started = time.perf_counter()
    renderer.render(view)
    elapsed = time.perf_counter() - started
    during = ticks[0] - before
    stop.set()
    counter.join()
    # Holding the GIL, render() would leave the counter where it was.
    assert during > 1000, f"the counter ran {during} times in the {elapsed * 1000:.0f} ms render()"


def test_context_managers_release_in_any_order():
    with snell.Device(validation=False) as device, snell.Scene.from_arrays([snell.Mesh(*SPHERE[:3])]) as scene:
        renderer = snell.Renderer(device, scene)
    # The device and scene are closed, the renderer still holds them: it renders on.
    assert renderer.render(snell.View(32, 24)).shape == (24, 32, 4)
    renderer.close()
