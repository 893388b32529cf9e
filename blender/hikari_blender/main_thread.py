"""Work that must run on Blender's main thread, asked for from the render
thread.

In Blender's window F12 calls RenderEngine.render on a render job's
thread, where bpy.context has no window and no active object; Blender's
glTF exporter needs both and fails there (KhronosGroup/glTF-Blender-IO
#1943), and operators and frame changes off the main thread race the
interface. The render thread hands such work to the main thread through
bpy.app.timers (which Blender's event loop runs, with its first window as
the context) and waits. Where render() already runs on the main thread
(`blender -b`, bpy.ops.render.render from a script) the work runs at once."""

import threading

# How long the main thread may take to start the work: its event loop runs
# timers many times a second, so a wait this long means it never will.
START_TIMEOUT_S = 30.0


class MainThreadUnavailable(RuntimeError):
    pass


def run_on_main_thread(work, schedule=None, start_timeout: float = START_TIMEOUT_S):
    """work() on the main thread: its result, or the exception it raised.
    `schedule(callback)` has the main thread call `callback` soon (default:
    bpy.app.timers.register)."""
    if threading.current_thread() is threading.main_thread():
        return work()
    if schedule is None:
        import bpy

        def schedule(callback):
            bpy.app.timers.register(callback, first_interval=0.0)

    started, finished = threading.Event(), threading.Event()
    outcome = {}

    def callback():
        started.set()
        try:
            outcome["value"] = work()
        except BaseException as error:  # handed to the waiting thread
            outcome["error"] = error
        finally:
            finished.set()
        return None  # a timer that returns None runs once

    schedule(callback)
    if not started.wait(start_timeout):
        raise MainThreadUnavailable(
            f"Blender's main thread did not take the scene export within {start_timeout:.0f} s "
            "(is its event loop running?)")
    finished.wait()
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]
