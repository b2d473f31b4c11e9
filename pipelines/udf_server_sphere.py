#!/usr/bin/python3
"""Reference voroudf exec: server (docs/exec-protocol.md), numpy only: the UDF of the sphere |x| = 0.5.
Use: sample-seeds --udf "exec:/usr/bin/python3 pipelines/udf_server_sphere.py" -o seeds0.ply"""
import struct, sys
import numpy as np
inp, out = sys.stdin.buffer, sys.stdout.buffer
name = b"udf_server_sphere.py (sphere r=0.5)"
out.write(b"VUDF" + struct.pack("<I6fI", 1, -0.6, -0.6, -0.6, 0.6, 0.6, 0.6, len(name)) + name)
out.flush()
while len(head := inp.read(4)) == 4:  # EOF: the client is done
    n = struct.unpack("<I", head)[0]
    x = np.frombuffer(inp.read(12 * n), dtype="<f4").reshape(n, 3).astype(np.float64)
    r = np.linalg.norm(x, axis=1)
    # Away from the closest point x*0.5/r: outwards outside, inwards inside; the centre picks +z's point.
    g = np.where(r[:, None] > 0, x / np.where(r > 0, r, 1)[:, None], [0.0, 0.0, 1.0])
    g *= np.where(r < 0.5, -1.0, 1.0)[:, None]
    out.write(struct.pack("<I", n) + np.abs(r - 0.5).astype("<f4").tobytes() + g.astype("<f4").tobytes())
    out.flush()
