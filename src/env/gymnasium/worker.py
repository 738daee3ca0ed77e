# sapnet-gymnasium-worker: the Python side of sapnet's Gymnasium bridge (src/env/gymnasium/).
# One Gymnasium environment, stepped on request. sapnet writes this file into a private
# folder of its own and runs `python <that file> <spec>`, the worker's current directory
# being that folder, where <spec> is JSON: {"id", "kwargs", "attributes",
# "max_episode_steps", "module_dir"}.
#
# Requests arrive on fd 3 and replies leave on fd 4: the environment's own prints (stdout)
# go, with stderr, to sapnet's log of the worker and can never be read as a reply. Every
# reply is one frame: a status byte (0 ok, 1 error), a u32 length, that many bytes.
#
#   start:     the spaces, JSON {"obs": n, "actions": k, "max_episode_steps": m,
#              "gymnasium": version}; or an error
#   request:   13 bytes: an opcode, a u32, a u64, little-endian; a set-state request is
#              followed by the state's f64s
#   step, reset, set-state: the observation (n f32), the reward (f64), terminated (u8),
#              truncated (u8)
#   get-state: the state's f64s
#   error:     UTF-8 text
#
# End of fd 3 ends the worker.
import os
import sys

# Nothing is imported from the folder this script is in or from a current directory: only
# the interpreter's own paths, the user's PYTHONPATH and the task's `module_dir`.
_here = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if p not in ("", ".", _here, os.getcwd())]

import json
import signal
import struct
import traceback

# Ctrl-C at the terminal is sapnet's to handle: it ends the worker by closing fd 3.
signal.signal(signal.SIGINT, signal.SIG_IGN)

REQUESTS = 3
REPLIES = 4
frame_head = struct.Struct("<BI")


def write_all(data):
    view = memoryview(data)
    while view:
        view = view[os.write(REPLIES, view):]


def send(status, payload):
    write_all(frame_head.pack(status, len(payload)) + payload)


def fail(message):
    send(1, message.encode())
    sys.exit(0)


spec = json.loads(sys.argv[1])
env_id = spec["id"]
if spec.get("module_dir"):
    sys.path.insert(0, spec["module_dir"])
try:
    import numpy as np
    import gymnasium
except ImportError as e:
    fail(f"Gymnasium is not installed for {sys.executable} ({e}): pip install {spec['pip']}")

kwargs = dict(spec.get("kwargs") or {})
if spec.get("max_episode_steps") is not None:
    kwargs["max_episode_steps"] = spec["max_episode_steps"]
try:
    env = gymnasium.make(env_id, **kwargs)
except gymnasium.error.DependencyNotInstalled as e:
    fail(f"{env_id}: {e}")
except gymnasium.error.Error as e:
    fail(f"{env_id}: {type(e).__name__}: {e}")
except Exception as e:
    fail(f"{env_id}: gymnasium.make raised {type(e).__name__}: {e}")

unwrapped = env.unwrapped
for name, value in (spec.get("attributes") or {}).items():
    if not hasattr(unwrapped, name):
        fail(f"{env_id}: attributes: the environment has no attribute {name!r} to set")
    setattr(unwrapped, name, value)

action_space = env.action_space
observation_space = env.observation_space
if not isinstance(action_space, gymnasium.spaces.Discrete) or int(action_space.start) != 0:
    fail(f"{env_id}: the action space is {action_space}: sapnet's DQNs choose among Discrete(n) actions 0..n-1")
if not isinstance(observation_space, gymnasium.spaces.Box) or len(observation_space.shape) != 1:
    fail(f"{env_id}: the observation space is {observation_space}: sapnet's Q-networks read a 1-D Box")
n = int(observation_space.shape[0])
time_limit = env.spec.max_episode_steps if env.spec is not None else None
send(0, json.dumps({
    "obs": n,
    "actions": int(action_space.n),
    "max_episode_steps": time_limit,
    "gymnasium": gymnasium.__version__,
}).encode())

read = os.read
request = struct.Struct("<BIQ")
tail = struct.Struct("<d??")
ok_size = 4 * n + tail.size
zero_tail = tail.pack(0.0, False, False)
step = env.step
reset = env.reset


def read_exactly(count):
    data = read(REQUESTS, count)
    if len(data) == count:
        return data
    while len(data) < count:
        chunk = read(REQUESTS, count - len(data))
        if not chunk:
            sys.exit(0)
        data += chunk
    return data


def error(message):
    send(1, f"{env_id}: {message}".encode())


f32 = np.dtype(np.float32)
# The ok reply of a step, written in place: one buffer, one write, no bytes joined.
reply = bytearray(frame_head.size + ok_size)
frame_head.pack_into(reply, 0, 0, ok_size)
obs_start = frame_head.size
obs_end = obs_start + 4 * n
pack_into = tail.pack_into


def observation(values):
    # Most tasks return float32 arrays of their Box's shape: sent as they are. Anything
    # else (float64, a list) is converted, so the reply keeps its size.
    if getattr(values, "dtype", None) == f32 and values.size == n:
        return values.tobytes()
    converted = np.asarray(values, dtype=np.float32).reshape(-1)
    if converted.size != n:
        raise ValueError(f"an observation of {converted.size} values, the space has {n}")
    return converted.tobytes()


while True:
    op, word, seed = request.unpack(read_exactly(request.size))
    try:
        if op == 0x53:  # 'S': step
            obs, reward, terminated, truncated, _ = step(word)
            reply[obs_start:obs_end] = observation(obs)
            pack_into(reply, obs_end, reward, terminated, truncated)
            write_all(reply)
        elif op == 0x52:  # 'R': reset, with a seed if the word is 1
            obs, _ = reset(seed=seed if word == 1 else None)
            send(0, observation(obs) + zero_tail)
        elif op == 0x54:  # 'T': set the state to `word` f64s that follow
            state = np.frombuffer(read_exactly(8 * word), dtype="<f8").copy()
            unwrapped.state = state
            get = getattr(unwrapped, "_get_ob", None)
            obs = get() if get is not None else state
            send(0, observation(obs) + zero_tail)
        elif op == 0x47:  # 'G': get the state
            state = getattr(unwrapped, "state", None)
            send(0, b"" if state is None else np.asarray(state, dtype="<f8").tobytes())
        else:
            error(f"unknown request {op}")
    except Exception as e:
        what = {0x53: "step", 0x52: "reset", 0x54: "setting the state"}.get(op, "a request")
        last = traceback.format_exception_only(type(e), e)[-1].strip()
        error(f"{what} raised {last}")
