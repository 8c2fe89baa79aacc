"""A robot without ROS, for ``semsearch ros live``: a rosbridge server on loopback whose robot is
the simulator (the tests' robot; docs/robot.md).

:class:`Rosbridge` speaks the part of the rosbridge v2 protocol (JSON over a WebSocket) that a
client of a ROS 2 robot uses: ``advertise``/``unadvertise``, ``publish``, ``subscribe``/
``unsubscribe`` and the ROS 2 actions ``send_action_goal`` (answered by ``action_feedback`` and
``action_result``) and ``cancel_action_goal``; anything else gets a ``status`` error. Like a ROS 2
topic of transient-local durability (``/map``, amcl's pose), a latched topic's last message is
given to each new subscriber. It runs an asyncio loop in a thread of its own.

:class:`SimRobot` is a door-search scenario's robot behind it, as a TurtleBot with a SLAM node, a
text detector and Nav2 would be: it publishes its map (``/map``, the belief its laser built: -1
never seen, 0 free, 100 occupied, whenever it changes), its pose (``/semsearch/pose``) and each
sign its cameras read (``/semsearch/detections``), and takes ``nav2_msgs/action/NavigateToPose``
goals on ``/navigate_to_pose``: a goal is a path planned by the scenario's navigator on the
robot's own map, followed ``robot.step`` metres per tick (a tick every ``period`` seconds of wall
time) with the simulator's motion and sensing, step by step as ``semsearch run`` moves; a new goal
replaces the one under way (Nav2's preemption: the old one ends ABORTED), and a goal ends
SUCCEEDED at its last waypoint or ABORTED when there is no path. With ``follow``, a PoseStamped
a client publishes on that topic is a goal too (a navigation stack that takes ``--publish-only``'s
goals). The robot moves only towards a goal: standing, it neither senses nor publishes. Its start and its generator are those of the
run of ``semsearch run`` for the same goal, episode and seed, so the two can be compared.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import json
import threading

import numpy as np

from ..navigation.motion import advance
from ..navigation.navigators import NAVIGATORS
from ..optional import lazy_module
from ..runner.specs import Loaded
from ..tasks.base import Observer
from ..tasks.doors import DoorFrame, DoorSensing, DoorTask
from ..tasks.episodes import episode_seed
from .bag import Messages, map_states, stamp_ns, step_of, to_json
from .robot import ABORTED, CANCELED, NAVIGATE_ACTION, SUCCEEDED

ws_server = lazy_module("websockets.asyncio.server", "ros")  # optional: the ros extra

NAVIGATE = NAVIGATE_ACTION[0]
LATCHED = ("/map", "/semsearch/pose")  # transient local, as a map server's and amcl's topics are


class Rosbridge:
    """A rosbridge v2 server on ``host`` (loopback), in a thread of its own (:meth:`start`,
    :meth:`stop`); the robot's side publishes with :meth:`publish` and serves actions registered
    with :attr:`actions` (name -> ``handler(client, goal_id, args)``). Everything but
    :meth:`start`, :meth:`stop` and :meth:`call` runs on the server's loop: from another thread,
    go through :meth:`call`."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0):
        self.host, self.port = host, port
        self.loop = asyncio.new_event_loop()
        self.subs: dict[str, dict] = {}  # topic -> {client: set of subscription ids}
        self.latched: dict[str, dict] = {}
        self.actions: dict = {}
        self.cancels: dict = {}  # action name -> handler(goal_id)
        self.handlers: dict = {}  # topic -> handler(msg): the robot's own subscriber to what the clients publish
        self.on_subscribe: dict = {}  # topic -> handler(): called when a client subscribes to it
        self.received: list = []  # (topic, msg) the clients published, in order
        self.ops: list = []  # every op the clients sent, in order (what the tests look at)
        self.advertised: dict[str, str] = {}
        self._thread = threading.Thread(target=self.loop.run_forever, name="rosbridge", daemon=True)
        self._server = None

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def start(self) -> "Rosbridge":
        self._thread.start()
        try:
            asyncio.run_coroutine_threadsafe(self._open(), self.loop).result(10)
        except BaseException:  # the port taken, say: no thread left behind
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(10)
            raise
        return self

    async def _open(self):
        # close_timeout 1 s (websockets' default is 10): a stand-in that is stopped closes its
        # connections at once rather than waiting on a client that has gone (the tests stop it
        # under load, where ten seconds per connection was more than they waited)
        self._server = await ws_server.serve(self._client, self.host, self.port, max_size=None, close_timeout=1)
        self.port = self._server.sockets[0].getsockname()[1]

    def stop(self) -> None:
        """Close the server and its loop (once; again does nothing)."""
        if not self._thread.is_alive():
            return

        async def close():
            for task in asyncio.all_tasks(self.loop):
                if task is not asyncio.current_task():
                    task.cancel()
            self._server.close()
            await self._server.wait_closed()
        if self._server is not None:
            try:  # bounded: a stand-in stopped on a loaded machine ends within seconds, its loop stopped either way
                asyncio.run_coroutine_threadsafe(close(), self.loop).result(5)
            except (TimeoutError, concurrent.futures.TimeoutError, concurrent.futures.CancelledError):
                pass
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(5)

    def call(self, fn, *args) -> None:
        """Run ``fn(*args)`` on the server's loop (from another thread)."""
        self.loop.call_soon_threadsafe(fn, *args)

    # -- the robot's side (on the loop) -------------------------------------------------
    def publish(self, topic: str, msg: dict) -> None:
        if topic in LATCHED:
            self.latched[topic] = msg
        text = json.dumps({"op": "publish", "topic": topic, "msg": msg})
        for client in list(self.subs.get(topic, {})):
            self._send(client, text)

    def action_feedback(self, client, action: str, goal_id: str, values: dict) -> None:
        self._send(client, json.dumps({"op": "action_feedback", "id": goal_id, "action": action, "values": values}))

    def action_result(self, client, action: str, goal_id: str, status: int, values: dict) -> None:
        self._send(client, json.dumps({"op": "action_result", "id": goal_id, "action": action, "values": values,
                                       "status": status, "result": True}))

    def _send(self, client, text: str) -> None:
        self.loop.create_task(self._deliver(client, text))

    @staticmethod
    async def _deliver(client, text):
        try:
            await client.send(text)
        except Exception:  # noqa: BLE001  a client gone: its messages are dropped, as rosbridge drops them
            pass

    # -- the clients' side ----------------------------------------------------------------
    async def _client(self, ws):
        try:
            async for text in ws:
                try:
                    msg = json.loads(text)
                    self.ops.append(msg)
                    self._op(ws, msg)
                except Exception as exc:  # noqa: BLE001  a bad message gets rosbridge's status error, not a closed socket
                    await ws.send(json.dumps({"op": "status", "level": "error", "msg": f"{type(exc).__name__}: {exc}"}))
        finally:
            for clients in self.subs.values():
                clients.pop(ws, None)

    def _op(self, ws, msg: dict) -> None:
        op = msg["op"]
        if op == "subscribe":
            self.subs.setdefault(msg["topic"], {}).setdefault(ws, set()).add(msg.get("id"))
            if msg["topic"] in self.latched:
                self._send(ws, json.dumps({"op": "publish", "topic": msg["topic"], "msg": self.latched[msg["topic"]]}))
            elif msg["topic"] in self.on_subscribe:
                self.on_subscribe[msg["topic"]]()
        elif op == "unsubscribe":
            ids = self.subs.get(msg["topic"], {}).get(ws, set())
            ids.discard(msg.get("id"))
            if not ids:
                self.subs.get(msg["topic"], {}).pop(ws, None)
        elif op == "advertise":
            self.advertised[msg["topic"]] = msg["type"]
        elif op == "unadvertise":
            self.advertised.pop(msg["topic"], None)
        elif op == "publish":
            self.received.append((msg["topic"], msg["msg"]))
            if msg["topic"] in self.handlers:
                self.handlers[msg["topic"]](msg["msg"])
            text = json.dumps({"op": "publish", "topic": msg["topic"], "msg": msg["msg"]})
            for client in list(self.subs.get(msg["topic"], {})):
                if client is not ws:
                    self._send(client, text)
        elif op == "send_action_goal":
            handler = self.actions.get(msg["action"])
            if handler is None:
                raise KeyError(f"no action server for {msg['action']}")
            handler(ws, msg["id"], msg.get("args", {}))
        elif op == "cancel_action_goal":
            handler = self.cancels.get(msg["action"])
            if handler is not None:
                handler(msg["id"])
        else:
            raise ValueError(f"op {op!r} is not served here")


class _Frames(Observer):
    """The signs the last frame read: [(sign index, label as read)]."""

    steps = True

    def __init__(self):
        self.reads: list = []

    def see(self, event) -> None:
        if isinstance(event, DoorFrame):
            self.reads = list(event.reads)


class SimRobot:
    """A door-search scenario's robot behind a :class:`Rosbridge` (see the module's text), for
    goal ``goal``'s first episode (or ``episode``) and repeat ``seed``, one step every ``period``
    seconds. ``distance`` and ``steps`` are what it has travelled; ``found_at`` the distance at
    the frame whose camera read the goal's sign (as ``semsearch run`` measures a run), None before."""

    def __init__(self, bridge: Rosbridge, loaded: Loaded, goal, seed: int = 0, episode=None, period: float = 0.02,
                 follow: str | None = None):
        task = loaded.task
        if not isinstance(task, DoorTask):
            raise TypeError("the simulated robot searches for door signs")
        self.bridge, self.task, self.period = bridge, task, period
        ep = task.as_episode(episode if episode is not None else goal)
        rng = np.random.default_rng(episode_seed(ep, seed, loaded.sc.experiment.base_seed))  # as Task.run seeds a run
        self.st = task.start_state(ep, rng)
        self.st.belief = task.new_belief()
        self.sensing = DoorSensing(task, ep.goal, rng)
        self.sensing.observer = self.frames = _Frames()
        self.navigator = NAVIGATORS[task.sc.navigation.navigator]()
        self.m = Messages()
        self.step_m = task.sc.robot.step
        self.path = None  # the goal's waypoints (xs, ys), and the next one's index
        self.i = 0
        self.goal_id = self.client = None
        self.found_at: float | None = None
        self.goals: list = []  # (goal id, x, y) as they came
        self.late: list = []  # for each goal, the steps the robot took after the pose the goal was planned on (0: in time)
        self.ended: list = []  # (goal id, status)
        self._last_map = None
        self._task = None
        bridge.call(bridge.actions.__setitem__, NAVIGATE, self._goal)  # on the loop, as everything of the bridge's
        bridge.call(bridge.cancels.__setitem__, NAVIGATE, self._cancel)
        if follow is not None:  # a navigation stack of its own that drives to each PoseStamped on this topic
            bridge.call(bridge.handlers.__setitem__, follow, lambda msg: self._goal(None, None, {"pose": msg}))

    @property
    def distance(self) -> float:
        return self.st.distance

    def start(self) -> "SimRobot":
        """Wait for a client: the first frame is sensed where the robot stands when one subscribes
        to the pose (the detections of that frame reach a client that subscribed to them before,
        as ros live does), then the ticks run."""
        def begin():
            if self._task is None:
                self._frame()
                self._task = self.bridge.loop.create_task(self._ticks())
        self.bridge.call(self.bridge.on_subscribe.__setitem__, "/semsearch/pose", begin)
        return self

    async def _ticks(self):
        while True:
            await asyncio.sleep(self.period)
            if self.path is not None:
                self._step()

    def _goal(self, client, goal_id: str, args: dict) -> None:
        pose = args["pose"]["pose"]["position"]
        x, y = float(pose["x"]), float(pose["y"])
        stamp = args["pose"].get("header", {}).get("stamp", {})
        planned = stamp.get("sec", 0) * 1_000_000_000 + stamp.get("nanosec", 0)
        self.late.append(self.st.steps - step_of(planned, self.step_m))  # steps taken since the pose it was planned on
        self.goals.append((goal_id, x, y))
        if self.path is not None:
            self._end(ABORTED)  # preempted by the new goal: Nav2 aborts it
        self.goal_id, self.client = goal_id, client
        b, fr = self.st.belief, self.task.world.frame
        r, c = (int(v) for v in fr.to_index(self.st.x, self.st.y))
        tr, tc = (int(v) for v in fr.to_index(x, y))
        if (r, c) == (tr, tc):
            self._end(SUCCEEDED)
            return
        b.refresh_derived()  # the clearance the path keeps, on the map as it is now
        p = self.navigator.plan(b, r, c, tr, tc)
        if p is None or len(p[0]) < 2:
            self._end(ABORTED)
            return
        self.path, self.i = fr.to_world(p[0], p[1]), 1

    def _cancel(self, goal_id: str) -> None:
        if goal_id == self.goal_id:
            self._end(CANCELED)

    def _end(self, status: int) -> None:
        self.ended.append((self.goal_id, status))
        if self.client is not None:
            self.bridge.action_result(self.client, NAVIGATE, self.goal_id, status, {"result": {}})
        self.goal_id = self.client = None
        self.path = None

    def _step(self) -> None:
        """One step of ``semsearch run``'s loop, the re-plan left to the client: move, sense,
        update, publish."""
        st = self.st
        px, py = self.path
        st.x, st.y, self.i, st.heading, moved = advance(px, py, self.i, st.x, st.y, st.heading, self.step_m)
        st.distance += moved
        st.steps += 1
        st.trail.append((st.x, st.y))
        self._frame()
        if self.path is not None and self.i >= len(px):
            self._end(SUCCEEDED)
        elif self.client is not None:
            self.bridge.action_feedback(self.client, NAVIGATE, self.goal_id, {"current_pose": to_json(self._pose())})

    def _frame(self) -> None:
        st, b = self.st, self.st.belief
        found, _ = self.sensing.sense(st)
        self.sensing.update(st)
        if found and self.found_at is None:
            self.found_at = st.distance
        states = map_states(b.seen, b.free)
        if self._last_map is None or (states != self._last_map).any():
            self._last_map = states
            self.bridge.publish("/map", to_json(self.m.grid(self._ns(), states, self.task.world.frame)))
        signs = self.task.world.signs
        for i, label in self.frames.reads:
            self.bridge.publish("/semsearch/detections", to_json(self.m.detection(signs, int(i), label)))
        self.bridge.publish("/semsearch/pose", to_json(self._pose()))

    def _pose(self):
        return self.m.pose_stamped(self._ns(), self.st.x, self.st.y, self.st.heading)

    def _ns(self) -> int:
        return stamp_ns(self.st.steps, self.step_m)

    def resume(self, on: bool) -> None:
        """Publish ``/explore/resume`` as an operator would (False: pause the explorer, True: go
        on); call it on the loop (:meth:`Rosbridge.call`)."""
        self.bridge.publish("/explore/resume", {"data": bool(on)})
