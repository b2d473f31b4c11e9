#!/usr/bin/python3
"""Pictures of voroudf files: PNG, 1-3 views side by side, rendered by VTK off screen.

Usage: pipelines/render.py FILE [-o OUT.png] [--reference MESH] [--views N] [--size WxH]

FILE is any voroudf PLY (the kind is read from its `comment voroudf KIND` line, docs/formats.md) or a mesh
(.obj .off .ply .stl):
  mesh (mesh.ply, thick.ply): shaded triangles; non-manifold edges (3+ faces) red, boundary edges blue;
  seeds: points coloured by rank (1 sheet grey, 2 edge orange, 3 corner red, 0 black);
  labels: the dense samples coloured by their region; edges (nm-edges.ply): red segments.
--reference draws a mesh in its own row below, seen from the same cameras (e.g. the ground truth).
Without a display (no $DISPLAY) it runs itself under xvfb-run (Debian's xvfb, pipelines/setup.sh).
Exit codes as the programs': 2 bad option, 3 unreadable input, 1 anything else.
"""
import argparse
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("file")
    p.add_argument("-o", "--output", help="PNG to write (default: FILE with .png)")
    p.add_argument("--reference", help="a mesh drawn in a second row")
    p.add_argument("--views", type=int, default=3, choices=[1, 2, 3])
    p.add_argument("--size", default="1200x400", help="pixels of one row: WIDTHxHEIGHT")
    a = p.parse_args()
    if not os.environ.get("DISPLAY") and not os.environ.get("VOROUDF_RENDER_NESTED"):
        if not shutil.which("xvfb-run"):
            sys.exit("render.py: error: no $DISPLAY and no xvfb-run (install Debian's xvfb: pipelines/setup.sh)")
        env = dict(os.environ, VOROUDF_RENDER_NESTED="1")
        sys.exit(subprocess.call(["xvfb-run", "-a", sys.executable] + sys.argv, env=env))
    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
        assert 16 <= w <= 8000 and 16 <= h <= 8000
    except (ValueError, AssertionError):
        print(f"render.py: error: --size must be WIDTHxHEIGHT in pixels, got '{a.size}'", file=sys.stderr)
        sys.exit(2)
    out = a.output or os.path.splitext(a.file)[0] + ".png"
    try:
        rows = [actors_of(a.file)] + ([actors_of(a.reference)] if a.reference else [])
    except (OSError, ValueError, KeyError) as e:
        print(f"render.py: error: {e}", file=sys.stderr)
        sys.exit(3)
    render(rows, a.views, w, h, out)
    print(f"render.py: wrote {out}", file=sys.stderr)


# ------------------------------------------------------------------------------------------------ input

def kind_of(path):
    if not path.lower().endswith(".ply"):
        return "mesh"
    with open(path, "rb") as f:
        head = f.read(4096).split(b"end_header")[0].decode("ascii", "replace")
    for line in head.splitlines():
        w = line.split()
        if len(w) >= 3 and w[0] == "comment" and w[1] == "voroudf":
            return w[2]
    return "mesh"


def read_mesh(path):
    """(vertices (V,3), triangles (F,3)) of a mesh file of any supported format."""
    import numpy as np
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    ext = os.path.splitext(path)[1].lower()
    if not os.path.isfile(path):
        raise OSError(f"{path}: no such file")
    if ext == ".off":
        import voroudf
        return voroudf.read_off(path)
    if ext == ".ply":
        try:
            import voroudf
            d = voroudf.read_ply(path)
            return d["vertex"][:, :3], d.get("face", np.zeros((0, 3), int))
        except ValueError:
            pass  # ASCII or big-endian: VTK's reader below
    reader = {".obj": vtk.vtkOBJReader, ".stl": vtk.vtkSTLReader, ".ply": vtk.vtkPLYReader}.get(ext)
    if reader is None:
        raise ValueError(f"{path}: not a mesh (.obj .off .ply .stl)")
    r = reader(); r.SetFileName(path); r.Update()
    tri = vtk.vtkTriangleFilter(); tri.SetInputData(r.GetOutput()); tri.Update()
    pd = tri.GetOutput()
    if pd.GetNumberOfPoints() == 0:
        raise ValueError(f"{path}: no vertices read")
    v = vtk_to_numpy(pd.GetPoints().GetData()).astype(float)
    cells = vtk_to_numpy(pd.GetPolys().GetData()).reshape(-1, 4)[:, 1:]
    return v, cells


def polydata(points, triangles=None, lines=None, colors=None):
    import numpy as np
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    pd = vtk.vtkPolyData()
    pts = vtk.vtkPoints(); pts.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    pd.SetPoints(pts)

    def cells(idx):
        idx = np.asarray(idx, dtype=np.int64)
        arr = np.hstack([np.full((len(idx), 1), idx.shape[1], np.int64), idx]).ravel()
        ca = vtk.vtkCellArray(); ca.SetCells(len(idx), numpy_to_vtkIdTypeArray(arr, deep=True))
        return ca
    if triangles is not None and len(triangles):
        pd.SetPolys(cells(triangles))
    if lines is not None and len(lines):
        pd.SetLines(cells(lines))
    if triangles is None and lines is None:
        pd.SetVerts(cells(np.arange(len(points)).reshape(-1, 1)))
    if colors is not None:
        c = numpy_to_vtk(np.ascontiguousarray(colors, dtype=np.uint8), deep=True)
        c.SetName("colors")
        pd.GetPointData().SetScalars(c)
    return pd


def actor(pd, color=None, point_size=0, line_width=0, scalars=False):
    import vtk
    m = vtk.vtkPolyDataMapper(); m.SetInputData(pd)
    # Surfaces are pushed back a little so that edges drawn on them stay visible (no z-fighting).
    m.SetResolveCoincidentTopologyToPolygonOffset()
    m.SetRelativeCoincidentTopologyPolygonOffsetParameters(2, 2)
    if not scalars:
        m.ScalarVisibilityOff()
    a = vtk.vtkActor(); a.SetMapper(m)
    if color:
        a.GetProperty().SetColor(*color)
    if point_size:
        a.GetProperty().SetPointSize(point_size)
        a.GetProperty().SetRenderPointsAsSpheres(True)
    if line_width:
        a.GetProperty().SetLineWidth(line_width)
        a.GetProperty().SetRenderLinesAsTubes(True)
        a.GetProperty().LightingOff()
    return a


def actors_of(path):
    import numpy as np
    if not os.path.isfile(path):
        raise OSError(f"{path}: no such file")
    kind = kind_of(path)
    if kind in ("seeds", "labels", "edges"):
        import voroudf
        d = voroudf.read_ply(path)
        v = d["vertex"][:, :3]
        if kind == "edges":
            return [actor(polydata(v, lines=d.get("edge", np.zeros((0, 2)))[:, :2].astype(int)), (1, 0, 0),
                          line_width=4)]
        if kind == "seeds":
            # the rank is the last property of a full seeds file (docs/formats.md)
            rank = d["vertex"][:, -1].astype(int) if d["vertex"].shape[1] >= 8 else np.ones(len(v), int)
            palette = np.array([[0, 0, 0], [170, 170, 170], [255, 140, 0], [230, 0, 0]], np.uint8)
            return [actor(polydata(v, colors=palette[np.clip(rank, 0, 3)]), point_size=6, scalars=True)]
        label = d["vertex"][:, 3].astype(np.int64)
        rng = np.random.default_rng(0)
        palette = rng.integers(40, 255, size=(max(int(label.max()) + 2, 1), 3)).astype(np.uint8)
        return [actor(polydata(v, colors=palette[np.clip(label, -1, None) + 1]), point_size=2, scalars=True)]
    import voroudf
    v, f = read_mesh(path)
    edges, counts = voroudf.edge_counts(f)
    out = [actor(polydata(v, triangles=f), (0.85, 0.85, 0.8))]
    if len(edges[counts >= 3]):
        out.append(actor(polydata(v, lines=edges[counts >= 3]), (1, 0, 0), line_width=4))
    if len(edges[counts == 1]):
        out.append(actor(polydata(v, lines=edges[counts == 1]), (0, 0.3, 1), line_width=3))
    return out


# ----------------------------------------------------------------------------------------------- output

def render(rows, views, w, h, out):
    import vtk
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(w, h * len(rows))
    cameras = [(0, -1, 0.35), (1, -1, 0.8), (1, 0.2, 0.1)][:views]  # front, three-quarter, side
    shared = None
    for r, row in enumerate(rows):
        for k, direction in enumerate(cameras):
            ren = vtk.vtkRenderer()
            y0 = 1 - (r + 1) / len(rows)
            ren.SetViewport(k / views, y0, (k + 1) / views, y0 + 1 / len(rows))
            ren.SetBackground(1, 1, 1)
            for a in row:
                ren.AddActor(a)
            if r == 0:
                ren.ResetCamera()
                cam = ren.GetActiveCamera()
                fp = cam.GetFocalPoint(); dist = cam.GetDistance()
                cam.SetPosition(fp[0] - direction[0] * dist, fp[1] + direction[1] * dist, fp[2] + direction[2] * dist)
                cam.SetViewUp(0, 0, 1)
                ren.ResetCamera()
                shared = shared or {}
                shared[k] = cam
            else:
                ren.SetActiveCamera(shared[k])
            win.AddRenderer(ren)
    win.Render()
    grab = vtk.vtkWindowToImageFilter(); grab.SetInput(win); grab.Update()
    tmp = out + ".tmp.png"
    png = vtk.vtkPNGWriter(); png.SetFileName(tmp); png.SetInputConnection(grab.GetOutputPort()); png.Write()
    os.replace(tmp, out)  # no half-written picture


if __name__ == "__main__":
    main()
