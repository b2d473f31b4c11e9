#!/usr/bin/python3
"""A learned UDF meshed through the voroudf package: fit a small MLP to the unsigned distance of a mesh
(PyTorch from Debian's python3-torch, CPU), mesh the network with voroudf.mesh, evaluate against the mesh.

Usage: PYTHONPATH=python VOROUDF_BIN=build/bin /usr/bin/python3 python/examples/learned_udf.py MESH.off
           [--seeds 2500] [--steps 1500] [--workdir DIR]

Training targets are the distances to 150k points sampled on the mesh (as NDF-style training data is made
from point clouds), so the learned field is off by about their spacing near the surface, and its gradient
is the network's autograd gradient: the noisy, smooth-at-the-kink field a learned UDF gives.
"""
import argparse
import os
import sys
import time

import numpy as np
import torch

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import voroudf  # noqa: E402


def sample_surface(v, f, n, rng):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    t = rng.choice(len(f), n, p=area / area.sum())
    r1, r2 = np.sqrt(rng.random(n)), rng.random(n)
    return (1 - r1)[:, None] * a[t] + (r1 * (1 - r2))[:, None] * b[t] + (r1 * r2)[:, None] * c[t]


def nearest_distance(q, cloud, chunk=1024):
    out = []
    for i in range(0, len(q), chunk):
        out.append(torch.cdist(q[i:i + chunk], cloud).min(dim=1).values)
    return torch.cat(out)


class Udf(torch.nn.Module):
    def __init__(self, width=128, frequencies=6):
        super().__init__()
        self.freq = 2.0 ** torch.arange(frequencies) * np.pi
        self.net = torch.nn.Sequential(torch.nn.Linear(3 + 6 * frequencies, width), torch.nn.Softplus(beta=100),
                                       torch.nn.Linear(width, width), torch.nn.Softplus(beta=100),
                                       torch.nn.Linear(width, width), torch.nn.Softplus(beta=100),
                                       torch.nn.Linear(width, 1))

    def forward(self, x):
        xf = x[:, :, None] * self.freq
        h = torch.cat([x, torch.sin(xf).flatten(1), torch.cos(xf).flatten(1)], dim=1)
        return torch.nn.functional.softplus(self.net(h)[:, 0], beta=100)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("mesh")
    p.add_argument("--seeds", type=int, default=2500)
    p.add_argument("--steps", type=int, default=1500)
    p.add_argument("--workdir", default="learned-udf")
    p.add_argument("--proj-tol-rel", type=float, default=3e-3,
                   help="projection tolerance of the stages; 0: the programs' own (1e-5, with a learned field's "
                        "floor accepted at a kink's bottom), which lets seeds follow the network's gradient lines "
                        "onto its rounded creases (docs/python.md)")
    a = p.parse_args()
    torch.manual_seed(0)
    torch.set_num_threads(os.cpu_count() or 1)
    rng = np.random.default_rng(0)
    v, f = voroudf.read_off(a.mesh)
    lo, hi = v.min(0), v.max(0)
    center, scale = (lo + hi) / 2, 1.0 / (hi - lo).max()  # the frame of --udf-normalize: largest extent 1
    v = (v - center) * scale
    cloud = torch.tensor(sample_surface(v, f, 150_000, rng), dtype=torch.float32)
    near = sample_surface(v, f, 60_000, rng)
    q = np.concatenate([near + rng.normal(0, 0.005, near.shape), near + rng.normal(0, 0.03, near.shape),
                        rng.uniform(-0.6, 0.6, (30_000, 3))])
    q = torch.tensor(q, dtype=torch.float32)
    t0 = time.time()
    d = nearest_distance(q, cloud)
    print(f"learned_udf: {len(q)} training points, targets in {time.time() - t0:.1f} s", file=sys.stderr)

    model = Udf()
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, a.steps)
    t0 = time.time()
    os.makedirs(a.workdir, exist_ok=True)
    saved = os.path.join(a.workdir, f"model-{a.steps}.pt")  # a second run meshes the same network again
    if os.path.exists(saved):
        model.load_state_dict(torch.load(saved))
    for step in range(0 if os.path.exists(saved) else a.steps):
        i = torch.randint(0, len(q), (8192,))
        loss = (model(q[i]) - d[i]).abs().mean()  # L1, as NDF
        opt.zero_grad(); loss.backward(); opt.step(); sched.step()
        if step % 500 == 0 or step == a.steps - 1:
            print(f"learned_udf: step {step} L1 {loss.item():.5f}", file=sys.stderr)
    train_s = time.time() - t0
    torch.save(model.state_dict(), saved)

    def udf(x):  # (N,3) float32 in the normalised frame -> distances, autograd gradients
        out_d, out_g = [], []
        for i in range(0, len(x), 65536):
            xi = torch.from_numpy(x[i:i + 65536]).requires_grad_(True)
            di = model(xi)
            gi, = torch.autograd.grad(di.sum(), xi)
            out_d.append(di.detach()); out_g.append(torch.nn.functional.normalize(gi, dim=1))
        return torch.cat(out_d), torch.cat(out_g)

    t0 = time.time()
    tol = f"--proj-tol-rel {a.proj_tol_rel}" if a.proj_tol_rel else None
    m = voroudf.mesh(udf, box=([-0.6] * 3, [0.6] * 3), seeds=a.seeds, workdir=a.workdir, sample_seeds=tol,
                     optimize_seeds=tol, build_gvd=tol)
    mesh_s = time.time() - t0
    # The reference in the same frame: the programs normalise the mesh the same way with --udf-normalize.
    ref = os.path.join(a.workdir, "reference.ply")
    write_mesh(ref, v, f)
    metrics = voroudf.evaluate(m, ref)
    print(m)
    print(f"training {train_s:.0f} s, meshing {mesh_s:.0f} s; exact CD {metrics['cd_exact_x1e3']:.2f}, exact HD "
          f"{metrics['hd_exact_x1e3']:.2f} (x1e3), TQ {metrics['tq']:.3f}, TD {metrics['td']}, "
          f"feature recall {metrics['feature_recall']:.3f}")


def write_mesh(path, v, f):
    header = ("ply\nformat binary_little_endian 1.0\ncomment voroudf mesh 1\n"
              f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n")
    rec = np.zeros(len(f), dtype=[("n", "u1"), ("v", "<i4", 3)])
    rec["n"], rec["v"] = 3, f
    with open(path, "wb") as fh:
        fh.write(header.encode()); fh.write(v.astype("<f4").tobytes()); fh.write(rec.tobytes())


if __name__ == "__main__":
    main()
