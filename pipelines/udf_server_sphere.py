#!/usr/bin/python3
"""Reference voroudf UDF server (docs/exec-protocol.md), numpy only: the UDF of the sphere |x| = 0.5.

As an exec: source, on stdin/stdout (started by each stage):
    sample-seeds --udf "exec:/usr/bin/python3 pipelines/udf_server_sphere.py" -o seeds0.ply
As a unix: source, one long-lived process serving every stage that connects (each connection gets its
own handshake and ends with EOF; connections are served in parallel threads):
    python3 pipelines/udf_server_sphere.py --unix /tmp/sphere.sock &
    sample-seeds --udf unix:/tmp/sphere.sock -o seeds0.ply
"""
import os, socketserver, struct, sys
import numpy as np

NAME = b"udf_server_sphere.py (sphere r=0.5)"


def sphere(x):
    r = np.linalg.norm(x, axis=1)
    # Away from the closest point x*0.5/r: outwards outside, inwards inside; the centre picks +z's point.
    g = np.where(r[:, None] > 0, x / np.where(r > 0, r, 1)[:, None], [0.0, 0.0, 1.0])
    g *= np.where(r < 0.5, -1.0, 1.0)[:, None]
    return np.abs(r - 0.5), g


def serve(inp, out):
    """One client: the handshake, then answers until EOF."""
    out.write(b"VUDF" + struct.pack("<I6fI", 1, -0.6, -0.6, -0.6, 0.6, 0.6, 0.6, len(NAME)) + NAME)
    out.flush()
    while len(head := inp.read(4)) == 4:  # EOF: the client is done
        n = struct.unpack("<I", head)[0]
        x = np.frombuffer(inp.read(12 * n), dtype="<f4").reshape(n, 3).astype(np.float64)
        d, g = sphere(x)
        out.write(struct.pack("<I", n) + d.astype("<f4").tobytes() + g.astype("<f4").tobytes())
        out.flush()


class Connection(socketserver.StreamRequestHandler):
    def handle(self):
        try:
            serve(self.rfile, self.wfile)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client went away (it ended or failed): nothing to answer


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--unix":
        if os.path.exists(sys.argv[2]):
            os.unlink(sys.argv[2])
        with socketserver.ThreadingUnixStreamServer(sys.argv[2], Connection) as server:
            server.daemon_threads = True
            server.serve_forever()
    else:
        serve(sys.stdin.buffer, sys.stdout.buffer)
