"""Write examples/map/style/crayon.png, style/crayon-segments.png and map.svg.

``crayon.png`` is a still painted exemplar for the ``still`` stylizer (seed 002, docs/still.md):
a small hand-painted map in crayon over a thin gouache wash, on cream paper. Water (top left)
is laid in horizontal wavy blue strokes, land in diagonal green crayon hatching with the paper
grain showing through, and a road across the land is a dark-ochre band with a wobbly,
darker hand-drawn outline; each region is darker where it meets another. ``crayon-segments.png``
is the region map the painting was painted from, pixel for pixel, in flat #0000ff (water),
#00ff00 (land) and #ff0000 (road): the region map is made first, then each region is painted
inside it, so the two align exactly.

``map.svg`` is the flat-coloured map to stylize with it: layer ``map`` (still) holds water
#3060d0, land #40a040 and a road #c03020, colours near the segment colours, so that each fill
takes the exemplar region of the nearest colour; its coastline and road differ from the
painting's. Layer ``boat`` (#f0e0c0) sails across the water by SMIL ``<animateTransform>``
over 1 s (24 frames at 24 fps).

Plain numpy and scipy (imageio to write the PNGs); a fixed seed, nothing fetched.

Run:  python examples/map/make_style.py
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

HERE = Path(__file__).parent
SIZE = 256
SEED = 2
WATER, LAND, ROAD = 0, 1, 2
SEGMENT_COLOURS = np.array([[0, 0, 255], [0, 255, 0], [255, 0, 0]], np.uint8)

PAPER = np.array([0.95, 0.92, 0.84])
# per region: gouache wash, crayon tints (light to dark), edge colour
WASH = {WATER: (0.66, 0.78, 0.90), LAND: (0.76, 0.85, 0.58), ROAD: (0.74, 0.56, 0.26)}
TINTS = {
    WATER: ((0.20, 0.40, 0.78), (0.12, 0.28, 0.66), (0.36, 0.58, 0.86), (0.10, 0.20, 0.52)),
    LAND: ((0.30, 0.60, 0.22), (0.46, 0.70, 0.26), (0.18, 0.45, 0.16), (0.60, 0.74, 0.30)),
    ROAD: ((0.62, 0.44, 0.16), (0.55, 0.37, 0.12), (0.70, 0.52, 0.22)),
}
EDGE = {WATER: (0.07, 0.16, 0.44), LAND: (0.12, 0.32, 0.10)}
OUTLINE = (0.30, 0.18, 0.06)

# --- the vector map (layer "map" still, layer "boat" moving) --------------------------------------------------
MAP_WATER, MAP_LAND, MAP_ROAD, BOAT = "#3060d0", "#40a040", "#c03020", "#f0e0c0"
COAST = ("M 0,0 L 256,0 L 256,128 C 236,136 222,164 196,160 C 170,156 158,186 128,182 "
         "C 100,178 92,150 64,158 C 40,165 22,146 0,150 Z")
BOAT_SHAPE = ("M 14,226 L 50,226 L 43,236 L 21,236 Z "    # hull
              "M 31,224 L 31,194 L 46,222 Z")              # sail
BOAT_MOVE = (0, 170, -4)  # translate from (0, 0) to (170, -4) over 1 s


def road_polygon(half_width=7.0, samples=48):
    """The map's road: a band about a gently curving line from the left edge to the right edge, inside the land."""
    x = np.linspace(-4.0, SIZE + 4.0, samples)
    y = 78.0 + 22.0 * np.sin(x / SIZE * 2.2 * np.pi + 0.4) + 10.0 * np.sin(x / SIZE * 5.0 * np.pi)
    dx, dy = np.gradient(x), np.gradient(y)
    norm = np.hypot(dx, dy)
    nx, ny = -dy / norm, dx / norm
    side_a = [(a, b) for a, b in zip(x + half_width * nx, y + half_width * ny)]
    side_b = [(a, b) for a, b in zip(x - half_width * nx, y - half_width * ny)][::-1]
    points = side_a + side_b
    return "M " + " L ".join(f"{a:.1f},{b:.1f}" for a, b in points) + " Z"


def svg_text():
    move_x, move_y = BOAT_MOVE[1], BOAT_MOVE[2]
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="{SIZE}" height="{SIZE}" viewBox="0 0 {SIZE} {SIZE}">
  <!-- Fluidymation example: a flat-coloured map (still) and a boat sailing across its water in 1 s,
       to be painted from style/crayon.png and its regions style/crayon-segments.png (written with
       this file by make_style.py). -->
  <g id="map" inkscape:label="map">
    <rect x="0" y="0" width="{SIZE}" height="{SIZE}" fill="{MAP_WATER}"/>
    <path fill="{MAP_LAND}" d="{COAST}"/>
    <path fill="{MAP_ROAD}" d="{road_polygon()}"/>
  </g>
  <g id="boat" inkscape:label="boat">
    <path fill="{BOAT}" d="{BOAT_SHAPE}"/>
    <animateTransform attributeName="transform" type="translate" from="0 0" to="{move_x} {move_y}"
                      begin="0s" dur="1s" fill="freeze"/>
  </g>
</svg>
"""


# --- the painting ----------------------------------------------------------------------------------------------
def smooth_noise(rng, sigma, shape=(SIZE, SIZE)):
    """Gaussian-filtered white noise, zero mean and unit standard deviation."""
    field = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    return (field - field.mean()) / field.std()


def largest_component(mask):
    labels, count = ndimage.label(mask)
    if count <= 1:
        return mask
    sizes = ndimage.sum(mask, labels, range(1, count + 1))
    return labels == 1 + int(np.argmax(sizes))


def region_map(rng):
    """(H, W) int: WATER, LAND or ROAD per pixel, with irregular, hand-drawn-looking borders."""
    ys, xs = np.mgrid[:SIZE, :SIZE] + 0.5
    # coastline: water in the upper left, a wobbly diagonal with a bay and a headland
    coast = (xs + ys - 236.0 + 26.0 * np.sin((xs - ys) / 34.0 + 0.7)
             + 14.0 * smooth_noise(rng, 14) + 3.0 * smooth_noise(rng, 3))
    water = ndimage.binary_opening(coast < 0, iterations=2)
    water = largest_component(water)
    water = ~largest_component(~water)  # no lakes
    # road: a wobbly band from the bottom edge to the right edge, across the land
    t = np.linspace(0.0, 1.0, 900)
    p0, p1, p2 = np.array([52.0, 264.0]), np.array([150.0, 150.0]), np.array([266.0, 118.0])
    line = (1 - t)[:, None] ** 2 * p0 + 2 * ((1 - t) * t)[:, None] * p1 + t[:, None] ** 2 * p2
    tangent = np.gradient(line, axis=0)
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1) / np.hypot(*tangent.T)[:, None]
    wobble = 4.0 * np.sin(t * 9.0 + 1.0) + 2.0 * np.sin(t * 23.0 + 2.0)
    line = line + wobble[:, None] * normal
    distance, nearest = cKDTree(line).query(np.stack([xs.ravel(), ys.ravel()], axis=1))
    distance, nearest = distance.reshape(SIZE, SIZE), nearest.reshape(SIZE, SIZE)
    half = 13.0 + 1.6 * np.sin(t * 13.0 + 0.3) + 1.0 * np.sin(t * 31.0)
    road = (distance + 1.2 * smooth_noise(rng, 2.5) < half[nearest]) & ~water
    road = ndimage.binary_opening(road, iterations=1)
    road = largest_component(road)
    labels = np.full((SIZE, SIZE), LAND, np.int32)
    labels[water] = WATER
    labels[road] = ROAD
    return labels, (line, tangent)


def paper_grain(rng):
    """(H, W) in [0, 1]: the paper's tooth, high where the crayon skips."""
    grain = 0.55 * smooth_noise(rng, 0.7) + 0.35 * smooth_noise(rng, 1.6)
    fibres = ndimage.gaussian_filter(rng.standard_normal((SIZE, SIZE)), (0.6, 3.0), mode="wrap")
    grain += 0.25 * fibres / fibres.std()
    grain = (grain - grain.min()) / (grain.max() - grain.min())
    return grain


class Canvas:
    def __init__(self, labels, grain, rng):
        self.labels, self.grain, self.rng = labels, grain, rng
        self.rgb = np.broadcast_to(PAPER, (SIZE, SIZE, 3)).copy()
        self.pressure = 1.0 + 0.18 * smooth_noise(rng, 20)  # the hand presses harder in places
        self.ys, self.xs = np.mgrid[:SIZE, :SIZE] + 0.5

    def lay(self, amount, tint, region, opacity=1.0, window=(slice(None), slice(None))):
        """Lay ``tint`` where ``amount`` (0..1) says, only inside ``region`` (in ``window`` of the canvas)."""
        a = np.clip(amount, 0.0, 1.0) * (self.labels[window] == region) * opacity
        self.rgb[window] = self.rgb[window] * (1 - a[..., None]) + np.asarray(tint) * a[..., None]

    def crayon(self, pressure, bite=0.55, softness=0.22, window=(slice(None), slice(None))):
        """Crayon coverage for a stroke ``pressure``: the wax catches the paper's peaks first."""
        return np.clip((pressure * self.pressure[window] - bite * self.grain[window] - (1 - bite) * 0.35)
                       / softness, 0.0, 1.0)

    def stroke(self, region, tint, x, y, angle, length, width, wave=(0.0, 40.0), strength=1.0, opacity=0.9):
        """One crayon stroke: a slightly wavy band, tapering at both ends, pressure uneven along it."""
        reach = length / 2 + width + abs(wave[0]) + 2
        x0, x1 = int(max(0, x - reach)), int(min(SIZE, x + reach + 1))
        y0, y1 = int(max(0, y - reach)), int(min(SIZE, y + reach + 1))
        if x0 >= x1 or y0 >= y1:
            return
        window = (slice(y0, y1), slice(x0, x1))
        xs, ys = self.xs[window] - x, self.ys[window] - y
        c, s = np.cos(angle), np.sin(angle)
        u, v = xs * c + ys * s, -xs * s + ys * c
        phase = self.rng.uniform(0, 2 * np.pi)
        v = v - wave[0] * np.sin(2 * np.pi * u / wave[1] + phase)
        across = np.clip(1.0 - (v / width) ** 2, 0.0, 1.0) ** 0.6
        along = np.clip((length / 2 - np.abs(u)) / (0.25 * length), 0.0, 1.0)
        press = (0.8 + 0.2 * np.sin(u / length * self.rng.uniform(3, 7) + phase)) * strength
        self.lay(self.crayon(across * along * press, window=window), tint, region, opacity, window)

    def points_in(self, region, count):
        ys, xs = np.nonzero(self.labels == region)
        pick = self.rng.integers(0, len(xs), count)
        return xs[pick] + self.rng.uniform(0, 1, count), ys[pick] + self.rng.uniform(0, 1, count)


def paint(labels, road_line, rng):
    grain = paper_grain(rng)
    canvas = Canvas(labels, grain, rng)
    # a thin, uneven gouache wash under each region, thinner where the paper's grain stands up
    for region, wash in WASH.items():
        body = 0.55 + 0.25 * smooth_noise(rng, 9) - 0.25 * (grain - 0.5)
        canvas.lay(body, wash, region)
    # water: horizontal wavy strokes, overlapping, four blues
    xs, ys = canvas.points_in(WATER, 420)
    for x, y in zip(xs, ys):
        tint = TINTS[WATER][rng.choice(4, p=(0.4, 0.25, 0.25, 0.1))]
        canvas.stroke(WATER, tint, x, y, rng.normal(0.0, 0.05), rng.uniform(28, 80), rng.uniform(2.0, 3.6),
                      wave=(rng.uniform(1.2, 2.6), rng.uniform(26, 48)), strength=rng.uniform(0.75, 1.05),
                      opacity=rng.uniform(0.55, 0.85))
    # land: diagonal crayon hatching, then a sparser cross-hatch in the darker green
    xs, ys = canvas.points_in(LAND, 1150)
    for x, y in zip(xs, ys):
        tint = TINTS[LAND][rng.choice(4, p=(0.45, 0.25, 0.15, 0.15))]
        canvas.stroke(LAND, tint, x, y, -0.95 + rng.normal(0.0, 0.07), rng.uniform(16, 34), rng.uniform(1.3, 2.0),
                      wave=(rng.uniform(0.2, 0.8), rng.uniform(30, 60)), strength=rng.uniform(0.8, 1.05),
                      opacity=rng.uniform(0.6, 0.9))
    xs, ys = canvas.points_in(LAND, 160)
    for x, y in zip(xs, ys):
        canvas.stroke(LAND, TINTS[LAND][2], x, y, 0.55 + rng.normal(0.0, 0.08), rng.uniform(10, 22),
                      rng.uniform(1.0, 1.5), wave=(0.4, 40.0), strength=rng.uniform(0.65, 0.9),
                      opacity=rng.uniform(0.4, 0.7))
    # road: ochre strokes along its line
    line, tangent = road_line
    for _ in range(320):
        i = rng.integers(0, len(line))
        angle = np.arctan2(tangent[i, 1], tangent[i, 0]) + rng.normal(0.0, 0.06)
        offset = rng.uniform(-12, 12)
        x = line[i, 0] - np.sin(angle) * offset
        y = line[i, 1] + np.cos(angle) * offset
        tint = TINTS[ROAD][rng.choice(3, p=(0.5, 0.25, 0.25))]
        canvas.stroke(ROAD, tint, x, y, angle, rng.uniform(20, 44), rng.uniform(1.6, 2.6), wave=(0.6, 50.0),
                      strength=rng.uniform(0.75, 1.05), opacity=rng.uniform(0.6, 0.9))
    # darker edges where regions meet: the colour pooled and pressed harder there
    for region, edge in EDGE.items():
        inside = ndimage.distance_transform_edt(labels == region)
        reach = 2.6 + 1.2 * smooth_noise(rng, 6)
        band = np.exp(-np.maximum(inside - 1.0, 0.0) / np.maximum(reach, 0.8)) * (labels == region)
        canvas.lay(canvas.crayon(0.25 + 0.8 * band, bite=0.45), edge, region, 0.75)
    # the road's wobbly outline, drawn just inside its edge with a dark crayon
    inside = ndimage.distance_transform_edt(labels == ROAD)
    centre = 1.9 + 0.6 * smooth_noise(rng, 7)
    line_width = np.maximum(1.25 + 0.3 * smooth_noise(rng, 10), 0.8)
    outline = np.clip(1.0 - ((inside - centre) / line_width) ** 2, 0.0, 1.0)
    canvas.lay(canvas.crayon(0.25 + 1.0 * outline, bite=0.5), OUTLINE, ROAD, 0.92)
    # the paper's tooth shows through everything a little
    shade = 1.0 - 0.07 * (grain - 0.5) - 0.02 * smooth_noise(rng, 30)
    return np.clip(canvas.rgb * shade[..., None], 0.0, 1.0)


def main():
    rng = np.random.default_rng(SEED)
    labels, road_line = region_map(rng)
    painting = paint(labels, road_line, rng)
    (HERE / "style").mkdir(exist_ok=True)
    iio.imwrite(HERE / "style" / "crayon.png", np.rint(painting * 255).astype(np.uint8))
    iio.imwrite(HERE / "style" / "crayon-segments.png", SEGMENT_COLOURS[labels])
    (HERE / "map.svg").write_text(svg_text())


if __name__ == "__main__":
    main()
