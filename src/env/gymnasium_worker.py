# The Python side of sapnet's Gymnasium bridge (src/env/gymnasium.rs): one Gymnasium
# environment, stepped on request over stdin/stdout. Run as `python -c <this> <spec>`,
# where <spec> is JSON: {"id", "kwargs", "attributes", "max_episode_steps"}.
#
# The first line on stdout is JSON: {"obs": n, "actions": k, "max_episode_steps": m,
# "gymnasium": version} once the environment is made and its spaces fit, else
# {"error": message}. Then each request, 13 bytes (an opcode, a u32, a u64, little-endian;
# set-state requests are followed by the state's f64s), is answered by one write:
#
#   ok:    0, the observation (n f32), the reward (f64), terminated (u8), truncated (u8)
#   error: 1, a u32 length and that many bytes of UTF-8, padded to the ok reply's size
#
# and for get-state: 0, a u32 count and that many f64. End of stdin ends the worker.
import json
import os
import struct
import sys
import traceback


def fail(message):
    sys.stdout.write(json.dumps({"error": message}) + "\n")
    sys.stdout.flush()
    sys.exit(0)


spec = json.loads(sys.argv[1])
env_id = spec["id"]
try:
    import numpy as np
    import gymnasium
except ImportError as e:
    fail(f"Gymnasium is not installed for {sys.executable} ({e}): pip install gymnasium")

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
sys.stdout.write(json.dumps({
    "obs": n,
    "actions": int(action_space.n),
    "max_episode_steps": time_limit,
    "gymnasium": gymnasium.__version__,
}) + "\n")
sys.stdout.flush()

read = os.read
write = os.write
request = struct.Struct("<BIQ")
tail = struct.Struct("<d??")
ok_size = 1 + 4 * n + tail.size
zero_tail = tail.pack(0.0, False, False)
step = env.step
reset = env.reset


def read_exactly(count):
    data = read(0, count)
    if len(data) == count:
        return data
    while len(data) < count:
        chunk = read(0, count - len(data))
        if not chunk:
            sys.exit(0)
        data += chunk
    return data


def error(message):
    body = f"{env_id}: {message}".encode()
    reply = b"\x01" + struct.pack("<I", len(body)) + body
    write(1, reply + bytes(max(0, ok_size - len(reply))))


f32 = np.dtype(np.float32)
# The ok reply of a step, written in place: one buffer, one write, no bytes joined.
reply = bytearray(ok_size)
obs_end = 1 + 4 * n
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
            reply[1:obs_end] = observation(obs)
            pack_into(reply, obs_end, reward, terminated, truncated)
            write(1, reply)
        elif op == 0x52:  # 'R': reset, with a seed if the word is 1
            obs, _ = reset(seed=seed if word == 1 else None)
            write(1, b"\x00" + observation(obs) + zero_tail)
        elif op == 0x54:  # 'T': set the state to `word` f64s that follow
            state = np.frombuffer(read_exactly(8 * word), dtype="<f8").copy()
            unwrapped.state = state
            get = getattr(unwrapped, "_get_ob", None)
            obs = get() if get is not None else state
            write(1, b"\x00" + observation(obs) + zero_tail)
        elif op == 0x47:  # 'G': get the state
            state = getattr(unwrapped, "state", None)
            values = b"" if state is None else np.asarray(state, dtype="<f8").tobytes()
            write(1, b"\x00" + struct.pack("<I", len(values) // 8) + values)
        else:
            error(f"unknown request {op}")
    except Exception as e:
        what = {0x53: "step", 0x52: "reset", 0x54: "setting the state"}.get(op, "a request")
        last = traceback.format_exception_only(type(e), e)[-1].strip()
        error(f"{what} raised {last}")
