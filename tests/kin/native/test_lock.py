"""kin.native.lock: one holder at a time (threads and processes), a deadline for waiters, no lock
file left behind."""
from __future__ import annotations

import threading
import time

import kin
from kin.native.lock import file_lock


def test_one_holder_at_a_time_and_the_file_is_removed(tmp_path):
    path = tmp_path / "x.lock"
    inside, overlap = [], []

    def work(k):
        with file_lock(path, 30, "x"):
            if inside:
                overlap.append(k)
            inside.append(k)
            time.sleep(0.05)
            inside.remove(k)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert overlap == [] and not path.exists()


def test_a_waiter_gives_up_at_its_deadline(tmp_path):
    path = tmp_path / "x.lock"
    with file_lock(path, 30, "the thing"):
        errors = []

        def wait():
            try:
                with file_lock(path, 0.3, "the thing"):
                    pass
            except kin.CompileError as e:
                errors.append(str(e))

        t = threading.Thread(target=wait)
        t.start()
        t.join(10)
    assert len(errors) == 1 and "another process building the thing" in errors[0]
    with file_lock(path, 0.3, "the thing"):  # free again
        pass
