"""Threads and memory: a call waiting on the Model releases the GIL (another Python thread runs
meanwhile, other calls answer), and a million calls do not grow the process."""

import threading
import time


ELBOW = "ecce_arm.elbow.position"


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS in /proc/self/status")


class Counter(threading.Thread):
    """Counts as fast as it can until stopped."""

    def __init__(self):
        super().__init__(daemon=True)
        self.count = 0
        self.stop = False

    def run(self):
        while not self.stop:
            self.count += 1


def test_a_python_thread_runs_while_step_waits(arm):
    counter = Counter()
    counter.start()
    try:
        # its rate alone (this thread waits on an Event, which releases the GIL)
        before = counter.count
        threading.Event().wait(0.3)
        alone = (counter.count - before) / 0.3
        start_count = counter.count
        began = time.monotonic()
        assert arm.step(100000) == 100000
        step_s = time.monotonic() - began
        during = counter.count - start_count
    finally:
        counter.stop = True
        counter.join(5)
    rate = during / step_s
    print(f"counter: {alone:,.0f}/s alone, {rate:,.0f}/s during step(100000) of {step_s:.2f} s "
          f"({during:,} increments)")
    assert step_s > 0.5  # long enough to tell
    # holding the GIL for the step would leave the counter at a few switch intervals' worth
    assert during > 1_000_000
    assert rate > 0.1 * alone


def test_other_calls_answer_while_a_long_step_runs(arm):
    outcome = {}

    def run():
        try:
            outcome["steps"] = arm.step(40000)
        except BaseException as error:  # noqa: B902 - handed to the test's thread
            outcome["error"] = error

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    seen = []
    deadline = time.monotonic() + 60
    while worker.is_alive() and time.monotonic() < deadline:
        status = arm.status()
        if status.state == "RUNNING":
            seen.append(status.steps)
            arm.get(ELBOW)
    worker.join(5)
    assert not worker.is_alive()
    assert outcome.get("steps") == 40000, outcome
    print(f"{len(seen)} status calls answered during the step, steps "
          f"{seen[:1]} .. {seen[-1:]}")
    assert len(set(seen)) >= 3  # answered between slices, and the step went on
    assert seen == sorted(seen)
    assert arm.status().steps == 40000


def test_a_million_gets_do_not_grow_the_process(arm):
    get = arm.get
    value = float(get(ELBOW))
    began = time.monotonic()
    for _ in range(10_000):  # warm-up: the allocator's and the ORB's pools
        get(ELBOW)
    warm_s = time.monotonic() - began
    print(f"warm-up: 10,000 get() in {warm_s:.2f} s ({10_000 / warm_s:,.0f}/s)")
    before = rss_kib()
    began = time.monotonic()
    for _ in range(1_000_000):
        get(ELBOW)
    took = time.monotonic() - began
    after = rss_kib()
    grown_mib = (after - before) / 1024
    print(f"1,000,000 get() in {took:.1f} s ({1_000_000 / took:,.0f}/s); VmRSS {before} kB -> "
          f"{after} kB ({grown_mib:+.2f} MiB)")
    assert float(get(ELBOW)) == value  # a million answers later, still the same reading
    assert grown_mib < 20.0
