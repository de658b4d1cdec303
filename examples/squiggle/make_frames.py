"""Write examples/squiggle/frames/0000.svg ... 0023.svg: a thick squiggle stroke being drawn on.

Plain Python, no dependencies, deterministic output. Each frame is a static SVG whose single
top-level <g inkscape:label="squiggle"> holds one stroked cubic-Bezier path; the drawn part grows
through stroke-dasharray/stroke-dashoffset, using the path length computed here by sampling.

Run:  python examples/squiggle/make_frames.py
"""
import math
import os

N_FRAMES = 24
SIZE = 256
STROKE = "#7a3db8"
STROKE_WIDTH = 16

# start point, then cubic segments (c1, c2, end); all absolute coordinates
START = (36.0, 168.0)
SEGMENTS = [
    ((56.0, 96.0), (92.0, 92.0), (104.0, 132.0)),
    ((116.0, 172.0), (146.0, 206.0), (164.0, 152.0)),
    ((178.0, 110.0), (186.0, 76.0), (208.0, 92.0)),
    ((228.0, 106.0), (230.0, 150.0), (216.0, 184.0)),
]


def _bezier(p0, p1, p2, p3, t):
    u = 1.0 - t
    return tuple(u * u * u * a + 3 * u * u * t * b + 3 * u * t * t * c + t * t * t * d
                 for a, b, c, d in zip(p0, p1, p2, p3))


def path_length(samples_per_segment=400):
    total = 0.0
    p0 = START
    for c1, c2, end in SEGMENTS:
        prev = p0
        for k in range(1, samples_per_segment + 1):
            q = _bezier(p0, c1, c2, end, k / samples_per_segment)
            total += math.hypot(q[0] - prev[0], q[1] - prev[1])
            prev = q
        p0 = end
    return total


def path_d():
    def pt(p):
        return f"{p[0]:g} {p[1]:g}"
    parts = [f"M {pt(START)}"]
    for c1, c2, end in SEGMENTS:
        parts.append(f"C {pt(c1)}, {pt(c2)}, {pt(end)}")
    return " ".join(parts)


def frame_svg(index, length):
    drawn = (index + 1) / N_FRAMES          # fraction of the stroke visible in this frame
    offset = length * (1.0 - drawn)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg"
     xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="{SIZE}" height="{SIZE}" viewBox="0 0 {SIZE} {SIZE}">
  <g id="squiggle" inkscape:label="squiggle">
    <path d="{path_d()}" fill="none" stroke="{STROKE}" stroke-width="{STROKE_WIDTH}"
          stroke-linecap="round" stroke-linejoin="round"
          stroke-dasharray="{length:.2f} {length:.2f}" stroke-dashoffset="{offset:.2f}"/>
  </g>
</svg>
"""


def main():
    out_dir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "frames")
    os.makedirs(out_dir, exist_ok=True)
    # a little longer than the sampled length so the last frame is fully drawn
    length = math.ceil(path_length()) + 1
    for i in range(N_FRAMES):
        with open(os.path.join(out_dir, f"{i:04d}.svg"), "w", encoding="utf-8", newline="\n") as f:
            f.write(frame_svg(i, length))


if __name__ == "__main__":
    main()
