# Round trip of a 4-byte request and a 40-byte reply through two pipes, parent and child
# pinned to one core (as the bridge pins its run thread and worker), nothing computed.
import os, sys, time
core = int(sys.argv[1]) if len(sys.argv) > 1 else 0
n = 200_000
r1, w1 = os.pipe(); r2, w2 = os.pipe()
pid = os.fork()
os.sched_setaffinity(0, {core})
if pid == 0:
    os.close(w1)
    reply = b"x" * 40
    while True:
        b = os.read(r1, 4)
        if not b: os._exit(0)
        os.write(w2, reply)
else:
    req = b"abcd"
    for _ in range(1000):
        os.write(w1, req); os.read(r2, 40)
    t = time.perf_counter()
    for _ in range(n):
        os.write(w1, req); os.read(r2, 40)
    dt = time.perf_counter() - t
    os.close(w1); os.waitpid(pid, 0)
    print(f"pinned to core {core}: {dt / n * 1e6:.2f} µs per round trip")
