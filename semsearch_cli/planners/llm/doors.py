"""``llm``: a language model as a door planner, on any OpenAI-compatible endpoint.

At each re-plan the planner shows the model the decision as text (the goal, the frame, the
robot's pose and distance so far, the signs read, the frontier targets it may drive to, numbered
nearest first along the path; see :func:`observation`) and reads its reply:

- ``mode: actor``: the model answers one target's number (or the last number: look at the
  nearest wall face no camera has read yet, what every door planner does when it returns None);
- ``mode: estimator``: the model answers, as JSON, its probability ``p_i`` that the goal lies
  beyond each target ``i``, and the planner chooses by expected cost. With ``d_i`` the path to
  target ``i`` (m) and ``d_mean`` the mean path to the targets shown, going to ``i`` costs
  ``d_i`` and, when the goal is not beyond it (probability ``1 - p_i``), about the way back and
  on to another target, ``d_i + d_mean``: ``cost_i = d_i + (1 - p_i) (d_i + d_mean)``. The
  probabilities are taken as given when they sum to 1 or less, and scaled to sum to 1 when they
  sum to more; the least cost wins (ties: the nearer target).

A reply that is empty, does not parse, names a target not offered or does not come (an HTTP
error after the client's retries, a timeout) is invalid: the model is asked again with the reason,
at most ``reasks`` times; then the planner takes the nearest target (its stated fallback) and
counts it. Every call, reply and fallback is counted in the run's row (``llm_calls``,
``tokens_in``, ``tokens_out``, ``invalid_replies``, ``fallbacks``, ``llm_s``) and kept in its
transcript (:mod:`semsearch_cli.planners.llm.transcript`). A run whose calls reach ``max_calls`` (or whose tokens reach
``max_run_tokens``) ends as ``budget``.

The targets are the frontier candidates every door planner gets, reachable ones only, at most
``max_targets`` of them, ordered by their path length from the robot (a search to every target).
The first listed is greedy's choice: the nearest by greedy's own search (which stops at the first
target it reaches, and is the one the path then reuses), ties drawn from the run's generator
exactly as greedy draws them. So a model that always answers 0 makes greedy's runs, draw for draw:
the harness adds nothing of its own to a decision.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from string import Template
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...errors import BudgetSpent, PlannerError, ScenarioError
from ..base import COST_COLUMNS, Decision, DoorPlanner, register_planner
from ..text import ANGLES_TEXT, answer_line, deg, spell
from .transcript import folder_text, header, index, read, run_key
from .client import Chat, Reply, prompt_path, require_openai
from .replies import parse_number, parse_probabilities

FIELDS = {  # the fields a prompt template may use ($name), each documented in docs/llm.md
    "observation": "the whole decision as text (every field below, in this order)",
    "goal": "the goal line: 'Goal: read the door sign 148.'",
    "label": "the goal's label alone: 148",
    "frame": "the frame and angle conventions",
    "pose": "where the robot is, its heading and the distance travelled so far",
    "signs": "the signs read so far, nearest first",
    "targets": "the numbered choices",
    "answer": "the answer line: which numbers may be answered",
}
SPLIT = ("=== system ===", "=== user ===")
REPEAT_CHARS = 2000  # characters of an invalid reply sent back with the re-ask (a reply of 20,000 is not sent back whole)


class LlmParams(BaseModel):
    """The ``llm`` planner's parameters (``{name: llm, base_url: ..., model: ...}``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    base_url: str = Field("http://localhost:8000/v1", description="the OpenAI-compatible endpoint (ends in /v1)")
    model: str = Field("", description="the model's name as the server knows it (required, unless replay)")
    mode: Literal["actor", "estimator"] = Field("actor", description="actor: answers a target; estimator: probabilities")
    api_key_env: str = Field("OPENAI_API_KEY", description="the environment variable that holds the key (never written)")
    temperature: float = Field(0.0, ge=0.0, le=2.0)
    max_tokens: int = Field(512, ge=1, le=1_000_000, description="tokens a reply may take")
    timeout_s: float = Field(60.0, gt=0.0, le=3600.0, description="s a request may take before it is retried")
    retries: int = Field(2, ge=0, le=10, description="retries of a request (timeouts, 429, 5xx), with backoff")
    max_calls: int = Field(2000, ge=1, le=1_000_000, description="calls per run; then the run ends as budget")
    max_run_tokens: int | None = Field(None, ge=1, description="tokens in and out per run; then the run ends as budget")
    reasks: int = Field(2, ge=0, le=10, description="times an invalid reply is asked again before the fallback")
    max_targets: int = Field(16, ge=1, le=254, description="frontier targets shown, nearest first")
    max_concurrent: int = Field(4, ge=1, le=256, description="requests in flight to the endpoint from this machine")
    replan_on_signs: bool = Field(False, description="also re-plan when a sign reaches belief.min_reads reads")
    prompt: str | None = Field(None, json_schema_extra={"path": True}, description="a prompt template file")
    replay: str | None = Field(None, json_schema_extra={"path": True}, description="replay the transcripts in this folder")
    replay_planner: str | None = Field(None, description="the planner label to replay when the folder holds several")


def load_prompt(path: str | None, mode: str) -> tuple[str, str, str]:
    """(system template, user template, SHA-256 of the file) of a prompt template file (the shipped
    one of ``mode`` when None); a :class:`ScenarioError` naming the file for a file without the two
    sections or with a field that is not one of :data:`FIELDS`."""
    p = Path(path) if path else prompt_path(f"doors-{mode}")
    try:
        raw = p.read_bytes()
        text = raw.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(str(p), "prompt", f"cannot read the prompt template ({exc})") from None
    lines = text.splitlines()
    if lines.count(SPLIT[0]) != 1 or lines.count(SPLIT[1]) != 1 or lines.index(SPLIT[0]) > lines.index(SPLIT[1]):
        raise ScenarioError(str(p), "prompt", f"a prompt template holds a line '{SPLIT[0]}' and, after it, a line "
                            f"'{SPLIT[1]}', each once; the text under each is that message")
    a, b = lines.index(SPLIT[0]), lines.index(SPLIT[1])
    system, user = "\n".join(lines[a + 1:b]).strip(), "\n".join(lines[b + 1:]).strip()
    for part in (system, user):
        t = Template(part)
        if not t.is_valid():
            raise ScenarioError(str(p), "prompt", "a '$' that starts no field; write '$$' for a dollar sign")
        bad = [f for f in t.get_identifiers() if f not in FIELDS]
        if bad:
            raise ScenarioError(str(p), "prompt", f"no field ${bad[0]}; the fields: {', '.join('$' + f for f in FIELDS)}")
    return system, user, hashlib.sha256(raw).hexdigest()


def observation(ctx, dist: np.ndarray, order: np.ndarray, cands, mode: str) -> dict:
    """The decision as the model reads it, field by field (:data:`FIELDS`): ``order`` the
    candidates shown (indices into ``cands``), ``dist`` their path lengths (m) by candidate."""
    b = ctx.belief
    label = str(ctx.goal)
    travelled = "" if not math.isfinite(ctx.distance) else f"; travelled {ctx.distance:.1f} m"
    f = {"goal": f"Goal: read the door sign {label}.", "label": label,
         "frame": ("Frame: x points east and y north, in metres; a target's distance is the length of the robot's path "
                   "to it, every other distance a straight line. " + ANGLES_TEXT),
         "pose": f"You are at x {ctx.x:.1f} m, y {ctx.y:.1f} m, heading {deg(ctx.heading)} deg{travelled}."}
    reads = b.reads.lists(np.arange(b.reads.n), b.spec.min_reads)
    signs = sorted(((str(lab), x - ctx.x, y - ctx.y) for lab, (_, x, y) in reads.items()), key=lambda s: s[1] ** 2 + s[2] ** 2)
    f["signs"] = ("Signs read so far, nearest first (where you stood when you read each): " + "; ".join(
        f"{lab} read {math.hypot(dx, dy):.1f} m away, bearing {deg(math.atan2(dy, dx))} deg" for lab, dx, dy in signs) + "."
        if signs else "No sign read yet.")
    xs, ys = b.frame.to_world(cands.rows[order], cands.cols[order])
    lines = [("Targets: frontier points on the edge of the explored area, nearest first along the path, each with the "
              "direction in which unexplored space goes on beyond it" + (", or look at a wall:" if mode == "actor" else ":"))]
    lines += [f"[{k}] {dist[i]:.1f} m along the path, bearing {deg(math.atan2(y - ctx.y, x - ctx.x))} deg, unexplored space "
              f"towards {deg(cands.theta[i])} deg" for k, (i, x, y) in enumerate(zip(order, xs, ys))]
    n = len(order)
    if mode == "actor":
        lines.append(f"[{n}] look at the nearest wall face no camera has read yet")
    f["targets"] = "\n".join(lines)
    f["answer"] = (answer_line(np.ones(n + 1, bool)) if mode == "actor" else
                   f"Answer with one JSON object mapping target numbers ({spell(range(n))}) to probabilities from 0 to 1.")
    f["observation"] = "\n".join(f[k] for k in ("goal", "frame", "pose", "signs", "targets", "answer"))
    return f


@register_planner("llm")
class LlmPlanner(DoorPlanner):
    """A language model on an OpenAI-compatible endpoint chooses the frontier target (actor), or
    estimates where the goal lies and the planner chooses by expected cost (estimator)."""

    Params = LlmParams
    rank = 60
    cost_columns = COST_COLUMNS
    service = True
    run_attributes = ("replan_on_signs",)

    def __init__(self, params: LlmParams):
        super().__init__(params)
        self.replan_on_signs = params.replan_on_signs
        self.run: dict = {}
        self.transcript: list[dict] = []
        self.calls = self.tokens_in = self.tokens_out = self.invalid = self.fallbacks = 0
        self.llm_s = 0.0
        self.decision = 0
        self.spent = ""
        self.dry_run = False  # set by a dry run: the first prompt is raised (FirstPrompt), nothing is called
        self._replay: list[dict] | None = None
        self._chat: Chat | None = None
        self._live = params  # the parameters the run behaves by (a replay's: its transcript's)
        if params.replay is None:
            fault = self.fault(params)
            if fault:
                raise PlannerError(f"llm: {fault[0]}: {fault[1]}")
            require_openai("<llm planner>")
            self.system, self.user, self.prompt_sha = load_prompt(params.prompt, params.mode)

    @classmethod
    def fault(cls, params: LlmParams) -> tuple[str, str] | None:
        """A model to call, or transcripts to replay, must be named."""
        if params.replay is None and not params.model.strip():
            return "model", ("name the model the server serves (e.g. model: qwen2.5-7b-instruct), or replay "
                             "transcripts (replay: DIR)")
        return None

    @classmethod
    def inputs(cls, params: LlmParams) -> str:
        """The prompt template's bytes' hash, or the replayed transcripts' (names and hashes)."""
        if params.replay is not None:
            return "replay\0" + folder_text(Path(params.replay))
        return "prompt\0" + load_prompt(params.prompt, params.mode)[2]

    # ---- the run ----------------------------------------------------------------------------
    def start_run(self, run: dict) -> None:
        """The run's identity (from the seat); a replay finds its transcript by it."""
        self.run = dict(run)
        if self.params.replay is None:
            self.transcript = [header("doors", run, self.public_params(), self.prompt_sha)]
            return
        found = index(Path(self.params.replay)).get(run_key(run), [])
        if self.params.replay_planner is not None:
            found = [(lab, p) for lab, p in found if lab == self.params.replay_planner]
        where = f"run {self.describe_run()}"
        if not found:
            raise PlannerError(f"replay of {where}: no transcript of this run in {self.params.replay}")
        if len({lab for lab, _ in found}) > 1:
            raise PlannerError(f"replay of {where}: {self.params.replay} holds transcripts of several planners "
                               f"({', '.join(sorted({lab for lab, _ in found}))}); name one with replay_planner")
        lines = read(found[0][1])
        head = lines[0]
        try:
            self._live = LlmParams(**{**head["params"], "replay": self.params.replay})
        except (TypeError, ValueError) as exc:
            raise PlannerError(f"transcript {found[0][1]}: its parameters do not read ({str(exc)[:200]})") from None
        self.replan_on_signs = self._live.replan_on_signs
        self._replay = [x for x in lines[1:] if x.get("type") == "call"]
        self.transcript = [dict(head)]

    def describe_run(self) -> str:
        r = self.run
        return f"{r.get('planner', 'llm')} goal {r.get('goal', '?')} episode {r.get('episode', '?')} seed {r.get('seed', '?')}" \
               + (f" stage {r['stage']}" if r.get("stage") else "")

    def public_params(self) -> dict:
        """The parameters as a transcript keeps them: all of them (the key's variable's name, never the key)."""
        return self.params.model_dump(exclude={"replay", "replay_planner"})

    def costs(self) -> dict:
        return {"llm_calls": self.calls, "tokens_in": self.tokens_in, "tokens_out": self.tokens_out,
                "invalid_replies": self.invalid, "fallbacks": self.fallbacks, "llm_s": round(self.llm_s, 3)}

    # ---- a decision -------------------------------------------------------------------------
    def finish_run(self) -> None:
        """A replay must use its transcript up: a run that asked fewer calls went another way."""
        if self._replay is not None and self.calls < len(self._replay):
            raise PlannerError(f"replay of run {self.describe_run()}: the run ended after {self.calls} calls, and the "
                               f"transcript holds {len(self._replay)} (the run went another way: another budget or map?)")

    def choose(self, ctx, cands):
        if self.params.replay is not None and self._replay is None:
            raise PlannerError("a replay finds each run's transcript by the run (scenario, goal, episode, seed): replay "
                               "through semsearch run or bench run, not as a policy of an environment")
        if len(cands) == 0:
            return None
        b, res = ctx.belief, ctx.belief.frame.res
        d = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 0).lengths(cands.rows, cands.cols) * res  # every target
        # then greedy's own search, last, so that the path to the target reuses it as greedy's does
        near = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 1).lengths(cands.rows, cands.cols)
        if not np.isfinite(near).any():
            return None
        best = np.flatnonzero(near == near.min())
        first = int(best[0] if best.size == 1 else ctx.rng.choice(best))  # greedy's draw, exactly
        if not math.isfinite(d[first]):
            d[first] = near[first] * res
        ok = np.flatnonzero(np.isfinite(d))
        rest = [int(i) for i in ok[np.lexsort((ok, d[ok]))] if i != first]
        order = np.asarray([first, *rest][:self._live.max_targets], np.int64)
        fields = observation(ctx, d, order, cands, self._live.mode)
        k = self.decision
        self.decision += 1
        pick, info = self.ask(k, fields, d[order])
        if pick is None:
            return None
        i = int(order[pick])
        return Decision(int(cands.rows[i]), int(cands.cols[i]), {"llm": pick, "D": float(d[i]), **info})

    def ask(self, k: int, fields: dict, dist: np.ndarray) -> tuple[int | None, dict]:
        """The model's choice at decision ``k``: a shown target's place (None: look at a wall), asked
        again on an invalid reply at most ``reasks`` times, then the fallback (the nearest, 0)."""
        live = self._live
        n = len(dist)
        if self._replay is None:
            system, user = Template(self.system).substitute(fields), Template(self.user).substitute(fields)
            messages = [{"role": "system", "content": system}, {"role": "user", "content": user}]
        else:
            messages = []
        reason, last = "", None
        for attempt in range(live.reasks + 1):
            self.check_budget()
            if attempt and self._replay is None and last is not None:  # after no reply at all (an HTTP error): the same messages again
                messages = messages + [{"role": "assistant", "content": last[:REPEAT_CHARS]},
                                       {"role": "user", "content": f"Your reply could not be used: {reason}. {fields['answer']}"}]
            if self.dry_run:
                raise FirstPrompt(messages)
            reply, messages = self.call(k, attempt, fields["observation"], messages)
            last = reply.text
            if reply.text is None:
                choice, reason = None, reply.error or "the reply is empty"
            elif live.mode == "actor":
                choice, reason = parse_number(reply.text, range(n + 1))
            else:
                choice, reason = parse_probabilities(reply.text, n)
            self.log_call(k, attempt, fields["observation"], messages, reply, choice, reason)
            if choice is not None:
                if live.mode == "actor":
                    return (None if choice == n else choice), {"attempts": attempt + 1}
                return self.by_expected_cost(choice, dist), {"attempts": attempt + 1}
            self.invalid += 1
        self.fallbacks += 1
        self.transcript.append({"type": "fallback", "decision": k, "choice": 0, "reason": reason})
        return 0, {"fallback": True}

    @staticmethod
    def by_expected_cost(p: dict[int, float], dist: np.ndarray) -> int:
        """The target of least expected cost (see the module docstring)."""
        prob = np.zeros(len(dist))
        for t, v in p.items():
            prob[t] = v
        if prob.sum() > 1.0:
            prob /= prob.sum()
        cost = dist + (1.0 - prob) * (dist + dist.mean())
        return int(np.argmin(cost))

    def check_budget(self) -> None:
        live = self._live
        if self.calls >= live.max_calls:
            self.spent = f"the llm planner made max_calls = {live.max_calls} calls"
        elif live.max_run_tokens is not None and self.tokens_in + self.tokens_out >= live.max_run_tokens:
            self.spent = f"the llm planner used max_run_tokens = {live.max_run_tokens} tokens"
        if self.spent:
            raise BudgetSpent(self.spent)

    def call(self, k: int, attempt: int, obs: str, messages: list) -> tuple[Reply, list]:
        """One call to the model (or, in a replay, the transcript's call ``attempt`` of decision
        ``k``, its observation checked against this run's)."""
        if self._replay is None:
            if self._chat is None:
                live = self._live
                self._chat = Chat(live.base_url, live.model, live.api_key_env, live.temperature, live.max_tokens,
                                  live.timeout_s, live.retries, live.max_concurrent)
            reply = self._chat.ask(messages)
            reply.latency_s = round(reply.latency_s, 6)  # as the transcript keeps it: a replay sums the same seconds
        else:
            item = next((x for x in self._replay if x.get("decision") == k and x.get("attempt") == attempt), None)
            where = f"replay of run {self.describe_run()}: decision {k + 1}"
            if item is None:
                raise PlannerError(f"{where}, call {attempt + 1}: the transcript holds no such call (it was made by "
                                   "another version of the planner, or the run went another way)")
            if item.get("observation") != obs:
                raise PlannerError(f"{where}: the observation differs from the transcript's ({first_difference(item.get('observation'), obs)})")
            messages = item.get("messages", [])
            reply = Reply(item.get("reply") if isinstance(item.get("reply"), str) else None, str(item.get("error") or ""),
                          _int(item.get("tokens_in")), _int(item.get("tokens_out")), str(item.get("model") or ""),
                          float(item.get("latency_s") or 0.0))
        self.calls += 1
        self.tokens_in += reply.tokens_in
        self.tokens_out += reply.tokens_out
        self.llm_s += reply.latency_s
        return reply, messages

    def log_call(self, k, attempt, obs, messages, reply: Reply, choice, reason) -> None:
        self.transcript.append({"type": "call", "decision": k, "attempt": attempt, "observation": obs, "messages": messages,
                                "reply": reply.text, "error": reply.error,
                                "choice": ({str(t): v for t, v in choice.items()} if isinstance(choice, dict) else choice),
                                "valid": choice is not None, "reason": reason, "tokens_in": reply.tokens_in,
                                "tokens_out": reply.tokens_out, "latency_s": round(reply.latency_s, 6), "model": reply.model})


class FirstPrompt(Exception):
    """A dry run's stop at the first call: ``messages``, what would have been sent."""

    def __init__(self, messages: list[dict]):
        super().__init__("dry run: the first prompt")
        self.messages = messages

    def text(self) -> str:
        return "\n".join(f"--- {m['role']} ---\n{m['content']}" for m in self.messages)


def first_difference(a, b) -> str:
    """Where the transcript's observation ``a`` and the run's ``b`` part: the first line that differs."""
    la, lb = str(a).splitlines(), str(b).splitlines()
    for n, (x, y) in enumerate(zip(la, lb), 1):
        if x != y:
            return f"line {n}: transcript {x[:80]!r}, run {y[:80]!r}"
    return f"the transcript's has {len(la)} lines, the run's {len(lb)}"


def _int(v) -> int:
    return int(v) if isinstance(v, int) and not isinstance(v, bool) else 0
