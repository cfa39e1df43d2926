#!/usr/bin/python3
"""Chooses the camera keyframes of configs/sim/calib-board.toml: views in which the whole board
(white margin included) stays inside the image of the scene's lens while its corners reach into
every corner and edge of the image, as mrcal's choreography asks (closeups, tilts up to ~45 degrees,
the whole imager covered). Prints the [[trajectory.keyframe]] tables. Needs python3-mrcal.

With --partial (configs/sim/calib-charuco.toml, a ChArUco board of the same size and place), the
board may leave the image: a view counts the inner corners whose two light squares (the markers
that name the corner) lie inside the image, large enough to read, needs at least --min-seen of them, and
brings the nearest of them to its target; a quarter of the views aim at each image corner, closer
up than a whole board could be there.

Usage: scripts/design-calib-keyframes.py [--seed N] [--views N]
       scripts/design-calib-keyframes.py --partial --seed 7 --views 36 --tries 1500 --margin 3 \
           --min-square-px 18 --corner-distance 0.25 0.5 --distance 0.25 0.5
"""
import argparse

import mrcal
import numpy as np

W, H = 640, 480
LENS = "LENSMODEL_OPENCV8"
INTRINSICS = np.array([520.0, 521.5, 323.0, 237.0, -0.28, 0.11, 0.0005, -0.0004, -0.02, 0.04, 0.01, 0.0])
# Inner corners (9 x 13, 20 mm) and the paper's outline (one white square of margin) in the world.
CORNERS = np.array([[-0.12 + 0.02 * i, 0.08 - 0.02 * j, 0.0] for j in range(9) for i in range(13)])
EDGE = np.linspace(-1, 1, 21)
OUTLINE = np.array([[x * 0.16, y * 0.12, 0.0] for x in EDGE for y in (-1, 1)] +
                   [[x * 0.16, y * 0.12, 0.0] for y in EDGE for x in (-1, 1)])


def camera_rotation(position, look_at, roll):
    """Columns x, y (down), z (forward) of the camera in the world, as the simulator builds them."""
    z = look_at - position
    z /= np.linalg.norm(z)
    up = np.array([0.0, 1.0, 0.0])
    y = -(up - z * (up @ z))
    y /= np.linalg.norm(y)
    x = np.cross(y, z)
    c, s = np.cos(roll), np.sin(roll)
    return np.column_stack([c * x + s * y, c * y - s * x, z])


def project(points, position, R):
    p_cam = (points - position) @ R
    if np.any(p_cam[:, 2] < 0.05):
        return None
    return mrcal.project(p_cam, LENS, INTRINSICS)


def inside(q, margin):
    return np.all((q[:, 0] > margin) & (q[:, 0] < W - 1 - margin) & (q[:, 1] > margin) & (q[:, 1] < H - 1 - margin))


# For --partial: the corners of the two light squares (the markers' squares) beside each inner
# corner; the board's square (x, y), x along a row and y down the rows from the top left, is light
# where x + y is odd, and spans world x from -0.14 + 0.02 x, y down from 0.10 - 0.02 y.
def _light_squares(j, i):
    out = []
    for y in (j, j + 1):
        for x in (i, i + 1):
            if (x + y) % 2 == 1:
                x0, y0 = -0.14 + 0.02 * x, 0.10 - 0.02 * y
                out += [[x0, y0, 0.0], [x0 + 0.02, y0, 0.0], [x0 + 0.02, y0 - 0.02, 0.0], [x0, y0 - 0.02, 0.0]]
    return out


MARKER_SQUARES = np.array([_light_squares(j, i) for j in range(9) for i in range(13)])  # 117 x 8 x 3
PARTIAL = {"on": False, "min_seen": 30, "margin": 4, "min_square_px": 0}


def seen_corners(position, R):
    """The inner corners whose two light squares lie inside the image (PARTIAL["margin"] px) and are
    at least PARTIAL["min_square_px"] across, or None when the board is behind the camera."""
    squares = project(MARKER_SQUARES.reshape(-1, 3), position, R)
    corners = project(CORNERS, position, R)
    if squares is None or corners is None:
        return None
    squares = squares.reshape(len(CORNERS), 8, 2)
    edge = np.mean([np.linalg.norm(squares[:, k] - squares[:, k + 1 if k % 4 < 3 else k - 3], axis=1)
                    for k in range(8)], axis=0)
    ok = np.array([inside(q, PARTIAL["margin"]) for q in squares]) & (edge >= PARTIAL["min_square_px"])
    return corners[ok]


def random_view(rng, distances):
    look_at = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.25, 0.25), 0.0])
    tilt = np.radians(rng.uniform(5, 45))
    azimuth = rng.uniform(0, 2 * np.pi)
    distance = rng.uniform(*distances)
    direction = np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)])
    position = look_at + distance * direction
    roll = np.radians(rng.uniform(-16, 16))
    return position, look_at, roll


def score_view(position, look_at, roll, target):
    """How close the board's inner corners come to the target image point, or None when the
    board (white margin included) is not wholly inside the image."""
    R = camera_rotation(position, look_at, roll)
    if PARTIAL["on"]:
        seen = seen_corners(position, R)
        if seen is None or len(seen) < PARTIAL["min_seen"]:
            return None
        return np.min(np.linalg.norm(seen - target, axis=1))
    outline = project(OUTLINE, position, R)
    if outline is None or not inside(outline, 2):
        return None
    corners = project(CORNERS, position, R)
    if not inside(corners, 11):
        return None
    return np.min(np.linalg.norm(corners - target, axis=1))


def best_view(rng, target, tries, distances):
    best = None
    for _ in range(tries):
        position, look_at, roll = random_view(rng, distances)
        score = score_view(position, look_at, roll, target)
        if score is not None and (best is None or score < best[0]):
            best = (score, position, look_at, roll)
    # Then creep towards the target: small random moves of the camera that keep the board inside.
    step = 0.02
    for _ in range(tries // 4):
        _, position, look_at, roll = best
        moved = (position + rng.normal(0, step, 3), look_at + np.append(rng.normal(0, step, 2), 0.0),
                 roll + rng.normal(0, 0.02))
        distance = np.linalg.norm(moved[0] - moved[1])
        tilt = np.degrees(np.arccos((moved[0] - moved[1])[2] / distance))
        if not (distances[0] <= distance <= distances[1] and 5 <= tilt <= 45 and abs(moved[2]) <= np.radians(16)):
            continue
        score = score_view(*moved, target)
        if score is not None and score < best[0]:
            best = (score, *moved)
    return best


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--views", type=int, default=60)
    parser.add_argument("--tries", type=int, default=3000)
    parser.add_argument("--corner-distance", type=float, nargs=2, default=(0.5, 1.0))
    parser.add_argument("--partial", action="store_true", help="views may show part of the board")
    parser.add_argument("--min-seen", type=int, default=30, help="--partial: inner corners a view must show")
    parser.add_argument("--margin", type=float, default=4, help="--partial: px between the image's edge and a seen corner's squares")
    parser.add_argument("--min-square-px", type=float, default=0,
                        help="--partial: a seen corner's squares at least this many px across (markers big enough to read)")
    parser.add_argument("--distance", type=float, nargs=2, default=(0.32, 0.65), help="camera distance, other views")
    args = parser.parse_args()
    PARTIAL["on"] = args.partial
    PARTIAL["min_seen"] = args.min_seen
    PARTIAL["margin"] = args.margin
    PARTIAL["min_square_px"] = args.min_square_px
    rng = np.random.default_rng(args.seed)
    corners = [(0, 0), (W - 1, 0), (0, H - 1), (W - 1, H - 1)]
    edges = [(W / 2, 0), (W / 2, H - 1), (0, H / 2), (W - 1, H / 2)]
    targets = (corners * 3 + edges * 2 + [(W / 2, H / 2)] * 4) * max(1, args.views // 30)
    if args.partial:
        targets = corners * (args.views // 12) + edges * (args.views // 18) + [(W / 2, H / 2)] * (args.views // 18)
    while len(targets) < args.views:
        targets.append((rng.uniform(0, W - 1), rng.uniform(0, H - 1)))
    targets = targets[: args.views]
    order = rng.permutation(len(targets))  # neighbouring keyframes far apart: no shared blur
    for frame, index in enumerate(order):
        # Close-ups pin the focal length and the distortion; in the image corners the whole board
        # (white margin included) only fits further away, where it is smaller, and the corners are
        # where a lens model is otherwise extrapolated.
        distances = tuple(args.corner_distance) if targets[index] in corners else tuple(args.distance)
        score, position, look_at, roll = best_view(rng, np.array(targets[index], float), args.tries, distances)
        print(f"[[trajectory.keyframe]]  # reaches {score:.0f} px from image point "
              f"({targets[index][0]:.0f}, {targets[index][1]:.0f})")
        print(f"time_s = {frame * 0.5:.1f}")
        print(f"position = [{position[0]:.3f}, {position[1]:.3f}, {position[2]:.3f}]")
        print(f"look_at = [{look_at[0]:.3f}, {look_at[1]:.3f}, 0.000]")
        print("up = [0.0, 1.0, 0.0]")
        print(f"roll_deg = {np.degrees(roll):.0f}")


if __name__ == "__main__":
    main()
