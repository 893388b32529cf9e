"""run_on_main_thread: the render thread's way to have the scene exported
on Blender's main thread (F12 in Blender's window renders off it)."""

import queue
import threading

import pytest


def from_worker(call):
    """call() on a worker thread while this (main) thread runs what is
    scheduled, as Blender's event loop runs timers: its outcome."""
    scheduled, outcome = queue.Queue(), {}

    def worker():
        try:
            outcome["value"] = call(scheduled.put)
        except BaseException as error:
            outcome["error"] = error

    thread = threading.Thread(target=worker)
    thread.start()
    while thread.is_alive():
        try:
            scheduled.get(timeout=0.01)()
        except queue.Empty:
            pass
    thread.join()
    return outcome


def test_on_the_main_thread_the_work_runs_at_once(addon):
    ran_on = []
    value = addon.main_thread.run_on_main_thread(lambda: ran_on.append(threading.current_thread()) or 7,
                                                 schedule=lambda _: pytest.fail("scheduled"))
    assert value == 7 and ran_on == [threading.main_thread()]


def test_from_another_thread_the_work_runs_on_the_main_thread(addon):
    ran_on = []

    def work():
        ran_on.append(threading.current_thread())
        return "exported"

    outcome = from_worker(lambda schedule: addon.main_thread.run_on_main_thread(work, schedule))
    assert outcome == {"value": "exported"}
    assert ran_on == [threading.main_thread()]


def test_the_works_error_reaches_the_waiting_thread(addon):
    def work():
        raise ValueError("no camera")

    outcome = from_worker(lambda schedule: addon.main_thread.run_on_main_thread(work, schedule))
    assert isinstance(outcome["error"], ValueError) and str(outcome["error"]) == "no camera"


def test_a_main_thread_that_never_takes_the_work_is_an_error_not_a_hang(addon):
    ran = []
    outcome = from_worker(lambda _: addon.main_thread.run_on_main_thread(
        lambda: ran.append(1), schedule=lambda callback: None, start_timeout=0.2))
    assert isinstance(outcome["error"], addon.main_thread.MainThreadUnavailable), outcome
    assert "main thread" in str(outcome["error"]) and not ran
