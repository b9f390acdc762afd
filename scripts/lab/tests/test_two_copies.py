"""two-copies.py, the written-down ghost check for Oats, on small text models built here: two
groups of cameras, each round its own cluster of points. The verdict must be "apart" only when
the clusters share no point, lie apart and keep one scale."""
import math
import os
import tempfile
import unittest

from lab_tool import run


def ring(centre, radius, first_id):
    """40 points (id, xyz) on a ring of `radius` round `centre` (in the x-z plane), with ids from
    `first_id`."""
    points = []
    for k in range(40):
        a = k * math.tau / 40
        points.append((first_id + k, [centre[0] + radius * math.cos(a),
                                      centre[1] + 0.1 * (k % 5),
                                      centre[2] + radius * math.sin(a)]))
    return points


def write_model(folder, first, second):
    """A text model: images 0000.png..0007.png at x = 0..7 see `first`, 0014.png..0022.png at
    x = 20..28 see `second`, unless it is empty (identity rotations: the centre is -t)."""
    images = []
    image_id = 1
    for frames, x0, seen in ((range(0, 8), 0.0, first), (range(14, 23), 6.0, second)):
        if not seen:
            continue
        for f in frames:
            c = [x0 + f, 0.0, 0.0]
            images.append(f"{image_id} 1 0 0 0 {-c[0]} {-c[1]} {-c[2]} 1 {f:04d}.png")
            images.append(" ".join(f"100 100 {p}" for p, _ in seen))
            image_id += 1
    points = {p: xyz for p, xyz in first + second}
    with open(os.path.join(folder, "images.txt"), "w") as f:
        f.write("\n".join(images) + "\n")
    with open(os.path.join(folder, "points3D.txt"), "w") as f:
        f.writelines(f"{p} {x} {y} {z} 128 128 128 0.5\n" for p, (x, y, z) in sorted(points.items()))
    with open(os.path.join(folder, "cameras.txt"), "w") as f:
        f.write("1 PINHOLE 640 480 500 500 320 240\n")


class TwoCopies(unittest.TestCase):
    def assert_verdict(self, first, second, expected):
        """The script's output for the two groups contains every one of `expected`."""
        with tempfile.TemporaryDirectory() as folder:
            write_model(folder, first, second)
            out = run("two-copies.py", folder, "0007.png", "0014.png")
        for e in expected:
            self.assertIn(e, out)

    def test_two_clusters_apart_at_one_scale_are_apart(self):
        self.assert_verdict(ring([3.5, 0, 10], 1.0, 1), ring([24, 0, 10], 1.5, 101),
                            ["shared 0,", "x: apart"])

    def test_groups_sharing_points_are_a_ghost(self):
        # The second group sees half the first's points besides its own cluster far away (a
        # model that merged part of the copies): the shared points alone decide.
        a = ring([3.5, 0, 10], 1.0, 1)
        self.assert_verdict(a, a[:20] + ring([24, 0, 10], 1.0, 101), ["shared 20,", "NOT apart"])

    def test_two_copies_of_points_in_one_place_are_a_ghost(self):
        self.assert_verdict(ring([3.5, 0, 10], 1.0, 1), ring([3.5, 0, 10], 1.0, 101),
                            ["shared 0,", "apart 0.0 spreads", "NOT apart"])

    def test_a_group_shrunk_by_a_link_without_scale_is_not_apart(self):
        self.assert_verdict(ring([3.5, 0, 10], 0.2, 1), ring([24, 0, 10], 1.5, 101),
                            ["shared 0,", "NOT apart"])

    def test_a_model_with_one_group_only_has_nothing_to_merge(self):
        self.assert_verdict(ring([3.5, 0, 10], 1.0, 1), [], ["8 images, not both groups"])

    def test_a_group_without_points_of_its_own_is_not_apart(self):
        # The second group's cameras see one point, one the first group sees too.
        a = ring([3.5, 0, 10], 1.0, 1)
        self.assert_verdict(a, a[:1], ["no point of its own: NOT apart"])


if __name__ == "__main__":
    unittest.main()
