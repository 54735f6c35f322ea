#!/usr/bin/python3
"""The mass-spring source's one-particle integrator tests (docs/models.md, "The source's
experiments"): one particle in one dimension under a known acceleration, each scheme's update of
docs/equations.md §4 applied to it, and the standard deviation of the position error over the
run against the exact trajectory, with the fixed step and with random steps.

1. a = -9.81 m/s^2, x0 = 0, v0 = 61.29 m/s, dt = 0.25 s, 25 steps;
2. x(t) = 2t^3 - 7t^2 + 5t (v0 = 5 m/s, a = 12t - 14);
3. x(t) = -sin t (v0 = -1 m/s, a = sin t).

The schemes are the code's (src/time/verlet_family.cpp, velocity_schemes.cpp) on a scalar:
positional Verlet is verlet-lagged (x+ = 2x - x- + dt^2 a, its first-order start x- = x0 - dt v0),
time-corrected Verlet is verlet/tc-verlet (x+ = x + (x - x-) dt/dt- + dt (dt + dt-)/2 a, start
x- = x0 - dt v0 + dt^2 a/2), with the published time-corrected form (dt^2 a) beside it, velocity
Verlet and Euler. Random steps are drawn uniformly from [0.5, 1.5] x the fixed step by a fixed
seed, over the same duration. Writes the table to stdout.
  benchmarks/one_particle.py > benchmarks/results/one-particle-<host>-<date>.md
"""
import math
import random

CASES = {
    "1: constant a": (lambda t: -9.81 * t * t / 2 + 61.29 * t, 61.29, lambda t: -9.81),
    "2: cubic": (lambda t: 2 * t**3 - 7 * t**2 + 5 * t, 5.0, lambda t: 12 * t - 14),
    "3: -sin t": (lambda t: -math.sin(t), -1.0, lambda t: math.sin(t)),
}
DT, STEPS = 0.25, 25


def steps_of(random_steps):
    if not random_steps:
        return [DT] * STEPS
    draw, steps, total = random.Random(7), [], 0.0
    while total < DT * STEPS - 1e-12:
        dt = min(DT * (0.5 + draw.random()), DT * STEPS - total)
        steps.append(dt)
        total += dt
    return steps


def run(scheme, exact, v0, accel, steps):
    """The positions at the end of each step."""
    x, v, t = exact(0.0), v0, 0.0
    out = []
    if scheme in ("positional Verlet",):
        previous, dt_previous = x - steps[0] * v0, steps[0]
    elif scheme.startswith("time-corrected"):
        previous, dt_previous = x - steps[0] * v0 + 0.5 * steps[0] ** 2 * accel(0.0), steps[0]
    for dt in steps:
        a = accel(t)
        if scheme == "Euler":
            x, v = x + dt * v, v + dt * a
        elif scheme == "velocity Verlet":
            x_next = x + dt * v + 0.5 * dt * dt * a
            v = v + 0.5 * dt * (a + accel(t + dt))
            x = x_next
        elif scheme == "positional Verlet":
            x, previous = 2 * x - previous + dt * dt * a, x
        elif scheme == "time-corrected Verlet":
            x, previous = x + (x - previous) * dt / dt_previous + dt * (dt + dt_previous) / 2 * a, x
        elif scheme == "time-corrected Verlet, published":
            x, previous = x + (x - previous) * dt / dt_previous + dt * dt * a, x
        dt_previous = dt
        t += dt
        out.append((t, x))
    return out


def main():
    schemes = ["positional Verlet", "time-corrected Verlet", "time-corrected Verlet, published",
               "velocity Verlet", "Euler"]
    print("| experiment | steps | " + " | ".join(schemes) + " |")
    print("|---|---|" + "---|" * len(schemes))
    for name, (exact, v0, accel) in CASES.items():
        for random_steps in (False, True):
            steps = steps_of(random_steps)
            cells = []
            for scheme in schemes:
                errors = [x - exact(t) for t, x in run(scheme, exact, v0, accel, steps)]
                mean = sum(errors) / len(errors)
                cells.append(f"{math.sqrt(sum((e - mean) ** 2 for e in errors) / len(errors)):.3e}")
            label = f"random ({len(steps)})" if random_steps else f"fixed {DT} s ({len(steps)})"
            print(f"| {name} | {label} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
