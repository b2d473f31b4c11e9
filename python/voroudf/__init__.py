"""voroudf from Python: mesh an unsigned distance field given as a callable (a learned UDF in this process)
or as a SPEC string, with the voroudf programs (docs/python.md).

    import numpy as np, voroudf
    def sphere(x):                      # (N,3) float32 -> distances (N,), gradients (N,3)
        r = np.linalg.norm(x, axis=1, keepdims=True)
        return np.abs(r[:, 0] - 0.5), np.where(r < 0.5, -1.0, 1.0) * x / np.maximum(r, 1e-12)
    m = voroudf.mesh(sphere, box=([-0.6] * 3, [0.6] * 3), seeds=1000)
    print(m)                            # Mesh(V vertices, F faces, E non-manifold edges)

A callable is served on a Unix socket from a thread of this process (`--udf unix:...`), so the model is
loaded once for the whole chain. numpy only; a callable may return torch tensors.
"""
import json
import os
import shlex
import shutil
import socket
import socketserver
import struct
import subprocess
import sys
import tempfile
import threading
from dataclasses import dataclass, field

import numpy as np

__all__ = ["mesh", "serve", "evaluate", "read_ply", "read_off", "edge_counts", "Mesh", "Server", "StageError", "UdfError"]

STAGES = ["sample-seeds", "optimize-seeds", "build-gvd", "thin-mesh"]


class StageError(RuntimeError):
    """A voroudf program failed: `exit_code` (docs/conventions.md) and its one-line `message`."""

    def __init__(self, program, exit_code, message):
        super().__init__(f"{program} failed with exit code {exit_code}: {message}")
        self.program, self.exit_code, self.message = program, exit_code, message


class UdfError(RuntimeError):
    """The UDF callable raised or returned something unusable while a stage was querying it."""


# ------------------------------------------------------------------------------------------- the server

def _as_array(value, dtype, shape):
    if hasattr(value, "detach"):  # a torch tensor
        value = value.detach().cpu().numpy()
    a = np.asarray(value, dtype=dtype)
    if a.shape != shape:
        raise UdfError(f"the UDF returned an array of shape {a.shape}, expected {shape}")
    if not np.all(np.isfinite(a)):
        raise UdfError("the UDF returned a non-finite value")
    return a


def _box6(box):
    b = np.asarray(box, dtype=np.float64).reshape(-1)
    if b.size != 6 or not np.all(b[:3] < b[3:]):
        raise ValueError("box must be (min xyz, max xyz) with min < max on every axis, got %r" % (box,))
    return b


class Server:
    """Serves `udf` on a Unix socket (the exec: protocol, docs/exec-protocol.md) from a daemon thread,
    one thread per connection. `spec` is the `--udf` value for the programs. Use as a context manager, or
    call close(). `error` holds the first exception the callable raised (the connection is then closed,
    so the stage fails with exit code 3)."""

    def __init__(self, udf, box, path=None, name="voroudf.serve"):
        self._udf, self._box, self.error = udf, _box6(box), None
        self._dir = None
        if path is None:
            self._dir = tempfile.mkdtemp(prefix="voroudf-")
            path = os.path.join(self._dir, "udf.sock")
        self.path, self.spec = path, "unix:" + path
        name_bytes = name.encode()[:4096]
        hello = b"VUDF" + struct.pack("<I6fI", 1, *self._box, len(name_bytes)) + name_bytes
        outer = self

        class Handler(socketserver.StreamRequestHandler):
            def handle(self):
                try:
                    self.wfile.write(hello)
                    self.wfile.flush()
                    while len(head := self.rfile.read(4)) == 4:
                        n = struct.unpack("<I", head)[0]
                        x = np.frombuffer(self.rfile.read(12 * n), dtype="<f4").reshape(n, 3)
                        try:
                            d, g = outer._udf(x.copy())
                            d = _as_array(d, "<f4", (n,))
                            g = _as_array(g, "<f4", (n, 3))
                        except Exception as e:  # noqa: BLE001 - reported to the caller of mesh()
                            if outer.error is None:
                                outer.error = e
                            return  # closing the connection ends the stage with exit code 3
                        self.wfile.write(struct.pack("<I", n) + d.tobytes() + g.tobytes())
                        self.wfile.flush()
                except (BrokenPipeError, ConnectionResetError):
                    pass

        self._server = socketserver.ThreadingUnixStreamServer(path, Handler)
        self._server.daemon_threads = True
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)
        self._thread.start()

    def close(self):
        self._server.shutdown()
        self._server.server_close()
        if os.path.exists(self.path):
            os.unlink(self.path)
        if self._dir:
            shutil.rmtree(self._dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def serve(udf, box, path=None):
    """Serves the callable `udf` ((N,3) float32 -> (N,) distances, (N,3) gradients) on a Unix socket for
    use from the shell (`--udf unix:PATH`). Returns the Server; it runs until close() or the end of the
    process (e.g. `voroudf.serve(f, box, "/tmp/f.sock"); input()` in a script)."""
    return Server(udf, box, path)


# ------------------------------------------------------------------------------------------ the programs

def _find_bin(bin_dir):
    """Where the programs are: `bin_dir`, $VOROUDF_BIN, PATH, or the source tree's build/bin."""
    candidates = [bin_dir, os.environ.get("VOROUDF_BIN")]
    on_path = shutil.which("sample-seeds")
    candidates.append(os.path.dirname(on_path) if on_path else None)
    candidates.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "build", "bin"))
    for c in candidates:
        if c and all(os.access(os.path.join(c, p), os.X_OK) for p in STAGES + ["evaluate"]):
            return os.path.abspath(c)
    raise FileNotFoundError("voroudf programs not found: pass bin_dir=, set VOROUDF_BIN, put them on PATH, "
                            "or build them (bash pipelines/test.sh)")


def _run(bin_dir, program, args, capture_stdout=False):
    """Runs one program; its log goes to our stderr as it comes. Raises StageError on failure."""
    proc = subprocess.Popen([os.path.join(bin_dir, program)] + args, stdout=subprocess.PIPE if capture_stdout
                            else subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    out_chunks, last_error = [], ""
    reader = None
    if capture_stdout:
        reader = threading.Thread(target=lambda: out_chunks.append(proc.stdout.read()), daemon=True)
        reader.start()
    for line in proc.stderr:
        sys.stderr.write(line)
        if ": error: " in line:
            last_error = line.split(": error: ", 1)[1].strip()
    rc = proc.wait()
    if reader:
        reader.join()
    if rc != 0:
        raise StageError(program, rc, last_error or "(no message)")
    return "".join(out_chunks)


def _args(value):
    if value is None:
        return []
    return shlex.split(value) if isinstance(value, str) else [str(v) for v in value]


@dataclass
class Mesh:
    """A voroudf mesh: vertices (V,3), triangles (F,3) of vertex indices, its non-manifold edges (E,2:
    edges shared by three or more triangles), and the path of every file the chain wrote."""
    vertices: np.ndarray
    faces: np.ndarray
    nonmanifold_edges: np.ndarray
    files: dict = field(default_factory=dict)

    @property
    def euler(self):
        """χ = V − E + F (unreferenced vertices are not counted)."""
        used = np.unique(self.faces)
        return len(used) - len(edge_counts(self.faces)[0]) + len(self.faces)

    def __repr__(self):
        return (f"Mesh({len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"{len(self.nonmanifold_edges)} non-manifold edges, χ = {self.euler})")


def edge_counts(faces):
    """The undirected edges of triangles (F,3) and how many triangles share each: (E,2), (E,)."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def mesh(udf, box=None, seeds=2500, seed=0, workdir=None, bin_dir=None, threads=0, sample_seeds=None,
         optimize_seeds=None, build_gvd=None, thin_mesh=None):
    """Meshes `udf` with the four voroudf programs and returns a Mesh.

    udf: a callable (N,3) float32 array -> (distances (N,), gradients (N,3)), served from this process on
         a Unix socket while the chain runs (`box` = (min xyz, max xyz) is then required: the domain the
         programs search); or a SPEC string (`shape:sphere`, a mesh path, `exec:...`, `unix:...`).
    seeds, seed: sample-seeds' --count and every stage's --seed.
    workdir: keep every intermediate file there (created); default: a temporary folder, removed.
    sample_seeds, optimize_seeds, build_gvd, thin_mesh: extra options for that stage (a string or a list).
    Raises StageError (exit code and message) when a stage fails, UdfError when the callable failed.
    """
    bin_dir = _find_bin(bin_dir)
    server = None
    if callable(udf):
        if box is None:
            raise ValueError("box is required with a callable UDF")
        server = Server(udf, box)
        spec = server.spec
    else:
        spec = str(udf)
    keep = workdir is not None
    work = os.path.abspath(workdir) if keep else tempfile.mkdtemp(prefix="voroudf-")
    os.makedirs(work, exist_ok=True)
    f = {k: os.path.join(work, k + ".ply") for k in ["seeds0", "seeds", "thick", "labels", "mesh", "nm-edges"]}
    common = ["--udf", spec, "--threads", str(threads)]
    try:
        _run(bin_dir, "sample-seeds", common + ["--count", str(seeds), "--seed", str(seed), "-o", f["seeds0"]]
             + _args(sample_seeds))
        _run(bin_dir, "optimize-seeds", common + ["--seed", str(seed), "-i", f["seeds0"], "-o", f["seeds"]]
             + _args(optimize_seeds))
        _run(bin_dir, "build-gvd", common + ["--seed", str(seed), "-i", f["seeds"], "-o", f["thick"],
                                             "--labels", f["labels"]] + _args(build_gvd))
        _run(bin_dir, "thin-mesh", common + ["-i", f["thick"], "-o", f["mesh"], "--nm-edges", f["nm-edges"]]
             + _args(thin_mesh))
        data = read_ply(f["mesh"])
        faces = data.get("face", np.zeros((0, 3), dtype=np.int64))
        edges, counts = edge_counts(faces)
        result = Mesh(data["vertex"][:, :3].astype(np.float64), faces, edges[counts >= 3],
                      dict(f) if keep else {})
    except StageError as e:
        if server is not None and server.error is not None:
            raise UdfError(f"the UDF raised {type(server.error).__name__}: {server.error}") from server.error
        raise e
    finally:
        if server is not None:
            server.close()
        if not keep:
            shutil.rmtree(work, ignore_errors=True)
    return result


def evaluate(mesh_or_path, reference, bin_dir=None, extra=None):
    """The paper's metrics of a mesh against a reference mesh file (docs/evaluate.md), as a dict."""
    bin_dir = _find_bin(bin_dir)
    if isinstance(mesh_or_path, Mesh):
        path = mesh_or_path.files.get("mesh")
        if path is None:
            raise ValueError("this Mesh has no file: call mesh(..., workdir=...) to keep it")
    else:
        path = str(mesh_or_path)
    return json.loads(_run(bin_dir, "evaluate", ["-i", path, "--reference", str(reference)] + _args(extra),
                           capture_stdout=True))


# -------------------------------------------------------------------------------------------- mesh files

def read_off(path):
    """(vertices (V,3), triangles (F,3)) of an ASCII OFF file (`#` comments; polygons split into fans)."""
    words = [w for line in open(path) for w in line.split("#")[0].split()]
    if not words or not words[0].endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    v = np.array(words[4:4 + 3 * nv], float).reshape(nv, 3)
    faces, k = [], 4 + 3 * nv
    for _ in range(nf):
        c = int(words[k])
        idx = [int(x) for x in words[k + 1:k + 1 + c]]
        k += 1 + c
        faces += [[idx[0], idx[i], idx[i + 1]] for i in range(1, c - 1)]
    return v, np.array(faces, dtype=np.int64).reshape(-1, 3)

# --------------------------------------------------------------------------------------------- PLY files

_PLY_TYPES = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "i2", "ushort": "u2",
              "int16": "i2", "uint16": "u2", "int": "i4", "uint": "u4", "int32": "i4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def read_ply(path, with_names=False):
    """Reads a binary little-endian PLY as voroudf writes it (docs/formats.md): a dict from element name to
    an array — (N, properties) for scalar elements, (F, 3) for triangle faces. With `with_names`, also a
    dict from element name to its property names in column order (property order is free in a PLY file)."""
    with open(path, "rb") as fh:
        raw = fh.read()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    lines = raw[:end].decode("ascii").splitlines()
    if lines[0] != "ply" or lines[1] != "format binary_little_endian 1.0":
        raise ValueError(f"{path}: not a binary little-endian PLY file")
    elements = []
    for line in lines:
        w = line.split()
        if w and w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w and w[0] == "property":
            elements[-1][2].append(w[1:])
    out, at = {}, end
    names = {name: [p[-1] for p in props] for name, _, props in elements}
    for name, count, props in elements:
        if props and props[0][0] == "list":
            _, ctype, itype, _ = props[0]
            dt = np.dtype([("n", "<" + _PLY_TYPES[ctype]), ("v", "<" + _PLY_TYPES[itype], 3)])
            rec = np.frombuffer(raw, dtype=dt, count=count, offset=at)
            if count and not np.all(rec["n"] == 3):
                raise ValueError(f"{path}: faces that are not triangles")
            out[name] = rec["v"].astype(np.int64)
        else:
            dt = np.dtype([(p[1], "<" + _PLY_TYPES[p[0]]) for p in props])
            rec = np.frombuffer(raw, dtype=dt, count=count, offset=at)
            out[name] = np.stack([rec[p[1]].astype(np.float64) for p in props], axis=1) if count else \
                np.zeros((0, len(props)))
        at += dt.itemsize * count
    return (out, names) if with_names else out
