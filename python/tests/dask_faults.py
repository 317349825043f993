"""Faults injected into a running Dask computation, shared by the LocalCluster and Slurm tests."""

import threading
import time


def when_busy(client, address, action, timeout=60.0):
    """Start a thread that calls ``action()`` once the worker at ``address`` holds tasks;
    returns (thread, event set once the action ran)."""
    done = threading.Event()

    def watch():
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if client.processing().get(address):
                action()
                done.set()
                return
            time.sleep(0.01)

    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    return thread, done
