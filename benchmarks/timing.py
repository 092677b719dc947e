"""Timing helper shared by the per-step profiles (step_profile_3_3.py, step_floor.py)."""
import time


def best(fn, repeat, blocks=5) -> float:
    """Seconds per call of fn, the fastest of ``blocks`` blocks (robust on a loaded machine)."""
    fastest = float("inf")
    for _ in range(blocks):
        start = time.perf_counter()
        for _ in range(repeat):
            fn()
        fastest = min(fastest, (time.perf_counter() - start) / repeat)
    return fastest
