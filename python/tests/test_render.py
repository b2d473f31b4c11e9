"""pipelines/render.py: pictures of a sphere mesh (no red: no non-manifold edge) and of crossing planes
(red along their branching line), and of a seeds file, at the asked size."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import voroudf

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
RENDER = os.path.join(ROOT, "pipelines", "render.py")


def read_png(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkPNGReader(); r.SetFileName(path); r.Update()
    w, h, _ = r.GetOutput().GetDimensions()
    return vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()).reshape(h, w, -1)


def red_pixels(img):
    rgb = img[:, :, :3].astype(int)
    return int(np.sum((rgb[:, :, 0] > 200) & (rgb[:, :, 1] < 60) & (rgb[:, :, 2] < 60)))


class RenderTest(unittest.TestCase):
    def picture(self, work, shape, seeds, name="mesh", *args):
        voroudf.mesh("shape:" + shape, seeds=seeds, workdir=work)
        out = os.path.join(work, name + ".png")
        r = subprocess.run([sys.executable, RENDER, os.path.join(work, name + ".ply"), "-o", out,
                            "--size", "600x200"] + list(args), capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        return read_png(out)

    def test_non_manifold_edges_are_red_and_a_sphere_has_none(self):
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            planes = self.picture(a, "crossing-planes", 1500)
            sphere = self.picture(b, "sphere", 800)
        self.assertEqual(planes.shape[:2], (200, 600))
        self.assertGreater(red_pixels(planes), 50)
        self.assertEqual(red_pixels(sphere), 0)
        self.assertGreater(np.sum(sphere[:, :, :3].sum(axis=2) < 600), 2000, "the sphere itself is drawn")

    def test_seeds_and_a_reference_row(self):
        with tempfile.TemporaryDirectory() as work:
            img = self.picture(work, "cube", 600, "seeds", "--reference", os.path.join(work, "mesh.ply"))
        self.assertEqual(img.shape[:2], (400, 600))  # two rows
        self.assertGreater(red_pixels(img), 20)  # the cube's corner seeds (rank 3)

    def test_a_missing_file_is_exit_code_3(self):
        r = subprocess.run([sys.executable, RENDER, "/nonexistent/mesh.ply", "-o", "/tmp/never.png"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 3, r.stderr)
        self.assertIn("no such file", r.stderr)
        self.assertFalse(os.path.exists("/tmp/never.png"))


if __name__ == "__main__":
    unittest.main()
