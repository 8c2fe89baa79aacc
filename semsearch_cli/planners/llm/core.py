"""What the ``llm`` planner does whatever it searches for: its parameters, its prompt templates,
asking the model (re-asks, the fallback, the budget), replaying a transcript, and counting the
cost. Each kind of search adds what the model reads and how its answer becomes a target:
:mod:`.doors`, :mod:`.objects`, :mod:`.indirect`.

A reply that is empty, does not parse, names a choice not offered or does not come (an HTTP
error after the client's retries, a timeout) is invalid: the model is asked again with the
reason, at most ``reasks`` times; then the planner takes its kind's stated fallback and counts it.
Every call, reply and fallback is counted in the run's row (``llm_calls``, ``tokens_in``,
``tokens_out``, ``invalid_replies``, ``fallbacks``, ``llm_s``) and kept in its transcript
(:mod:`.transcript`). A run whose calls reach ``max_calls`` (or whose tokens reach
``max_run_tokens``) ends as ``budget``.

A model that does not answer is never a result: a run whose first ``unavailable_after``
decisions (3) all fell back (every call of each invalid), or more than ``max_fallback_share``
(one half) of whose decisions fell back by its end, stops with :class:`~semsearch_cli.errors.Unavailable`
(outcome ``error``, a message that starts ``unavailable:`` and says why; the same command runs it
again). Before a batch's first run, :meth:`LlmCore.preflight` looks at the endpoint once
(:func:`.client.preflight`).

``mode: estimator`` (door and object search): the model answers, as JSON, its probability
``p_i`` that the goal lies at (beyond) each choice ``i``, and the planner chooses by expected
cost. With ``d_i`` the distance to choice ``i`` (m) and ``d_mean`` the mean over the choices
offered, going to ``i`` costs ``d_i`` and, when the goal is not there (probability ``1 - p_i``),
about the way back and on to another choice, ``d_i + d_mean``: ``cost_i = d_i + (1 - p_i) (d_i +
d_mean)``. The probabilities are taken as given when they sum to 1 or less, and scaled to sum to
1 when they sum to more; the least cost wins (ties: the lower number).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from string import Template
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from ...credentials import looks_like_key
from ...errors import BudgetSpent, PlannerError, ScenarioError, Unavailable
from ..base import COST_COLUMNS, Planner
from .client import MISSING, Chat, Reply, constraint, openai_installed, prompt_path, require_openai, url_fault
from .client import preflight as look_at_endpoint
from .replies import grammar, parse_choice, parse_number, parse_probabilities, schema
from .transcript import files, folder_text, header, index, read, replan_on_signs, run_key

FIELDS = {  # kind -> the fields a prompt template may use ($name), each documented in docs/llm.md
    "doors": {
        "observation": "the whole decision as text (every field below, in this order)",
        "goal": "the goal line: 'Goal: read the door sign 148.'",
        "label": "the goal's label alone: 148",
        "frame": "the frame and angle conventions",
        "pose": "where the robot is, its heading and the distance travelled so far",
        "signs": "the signs read so far, nearest first",
        "targets": "the numbered choices",
        "answer": "the answer line: which numbers may be answered",
    },
    "objects": {
        "observation": "the whole decision as text (every field below, in this order)",
        "goal": "the request: 'Goal: find a mug; the request was made at hour 12 of the day.'",
        "frame": "the frame and angle conventions",
        "pose": "where the robot is, its heading and the distance travelled so far",
        "places": "the numbered places, each with its distance, bearing, whether it was viewed, and the log's detections",
        "answer": "the answer line: which numbers may be answered",
    },
    "indirect": {
        "observation": "the whole decision as text (every field below, in this order)",
        "goal": "the target, the room, the camera's range and the time used",
        "frame": "the frame and angle conventions",
        "pose": "where the robot is and its heading",
        "objects": "the other objects detected, where",
        "likeliest": "the five likeliest cells of the target on the robot's map, with their probabilities",
        "choices": "how an answer names a pose of the lattice",
        "answer": "the answer line: which numbers may be answered",
    },
}
MODES = {"doors": ("actor", "estimator"), "objects": ("actor", "estimator"), "indirect": ("actor",)}
SPLIT = ("=== system ===", "=== user ===")
EXAMPLE = ("=== example user ===", "=== example assistant ===")  # a worked exchange, between the two (optional, repeatable)
ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,127}")  # an environment variable's name, as api_key_env takes it
REPEAT_CHARS = 2000  # characters of an invalid reply sent back with the re-ask (a reply of 20,000 is not sent back whole)


class LlmParams(BaseModel):
    """The ``llm`` planner's parameters (``{name: llm, base_url: ..., model: ...}``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    base_url: str = Field("http://localhost:8000/v1", description="the OpenAI-compatible endpoint (ends in /v1)")
    model: str = Field("", description="the model's name as the server knows it (required, unless replay)")
    mode: Literal["actor", "estimator"] = Field("actor", description="actor: answers a choice; estimator: probabilities "
                                                "(door and object search)")
    api_key_env: str = Field("OPENAI_API_KEY", description="the environment variable that holds the key (never written)")
    temperature: float = Field(0.0, ge=0.0, le=2.0)
    seed: int | None = Field(None, ge=0, le=2**31 - 1, description="sent with every request, for servers that sample "
                             "with one; kept with each call in the transcript")
    reply_format: Literal["text", "json_schema", "json_object", "grammar"] = Field(
        "text", description="text: the reply read as written, re-asked when invalid; json_schema, json_object or grammar: "
        "the server asked to keep the reply to the choices offered (OpenAI's structured outputs; llama.cpp's JSON schema "
        "or GBNF grammar)")
    max_tokens: int = Field(512, ge=1, le=1_000_000, description="tokens a reply may take")
    timeout_s: float = Field(60.0, gt=0.0, le=3600.0, description="s a request may take before it is retried")
    retries: int = Field(2, ge=0, le=10, description="retries of a request (timeouts, 429, 5xx), with backoff")
    max_calls: int = Field(2000, ge=1, le=1_000_000, description="calls per run; then the run ends as budget")
    max_run_tokens: int | None = Field(None, ge=1, description="tokens in and out per run; then the run ends as budget")
    reasks: int = Field(2, ge=0, le=10, description="times an invalid reply is asked again before the fallback")
    unavailable_after: int = Field(3, ge=0, le=1000, description="a run whose first this many decisions all fell back "
                                   "ends error (unavailable); 0: never")
    max_fallback_share: float = Field(0.5, ge=0.0, le=1.0, description="a run more of whose decisions fell back ends "
                                      "error (unavailable); 1: never")
    max_targets: int = Field(16, ge=1, le=254, description="door search: frontier targets shown, nearest first")
    lattice: float = Field(0.5, ge=0.05, le=5.0, description="indirect search: m between the lattice points offered")
    max_concurrent: int = Field(4, ge=1, le=256, description="requests in flight to the endpoint from this machine")
    replan_on_signs: bool = Field(False, description="door search: also re-plan when a sign reaches belief.min_reads reads")
    prompt: str | None = Field(None, json_schema_extra={"path": True}, description="a prompt template file")
    replay: str | None = Field(None, json_schema_extra={"path": True}, description="replay the transcripts in this folder")
    replay_planner: str | None = Field(None, description="the planner label to replay when the folder holds several")

    @field_validator("api_key_env")
    @classmethod
    def _a_variable_not_a_key(cls, v: str) -> str:
        """``api_key_env`` names a variable: a key written in its place (``sk-...``, or anything
        that is not a variable's name) would be written into the label, so it is refused."""
        if not ENV_NAME.fullmatch(v) or looks_like_key(v):
            raise ValueError("api_key_env must be the name of the environment variable that holds the key (letters, digits "
                             "and _, e.g. OPENAI_API_KEY), never the key itself, which would be written into the label, "
                             "rows and reports: export OPENAI_API_KEY=<your key> and leave api_key_env out, or name your "
                             "own variable")
        return v


def load_prompt(path: str | None, kind: str, mode: str) -> tuple[str, str, str]:
    """(system template, user template, SHA-256 of the file) of a prompt template file for ``kind``
    (the shipped ``<kind>-<mode>.txt`` when None); a :class:`ScenarioError` naming the file for a
    file without the two sections or with a field that is not one of ``FIELDS[kind]``. Its worked
    examples: :func:`load_examples`."""
    system, user, _, sha = _read_prompt(path, kind, mode)
    return system, user, sha


def load_examples(path: str | None, kind: str, mode: str) -> list[dict]:
    """The worked exchanges of a prompt template, as chat messages sent between the system message
    and the decision (``=== example user ===`` then ``=== example assistant ===``, each pair once or
    more, between the two sections; since 0.4.0): a small model that only echoes the text it is
    given answers in the format asked once it has seen one answer (docs/llm.md)."""
    return _read_prompt(path, kind, mode)[2]


def _read_prompt(path: str | None, kind: str, mode: str) -> tuple[str, str, list[dict], str]:
    p = Path(path) if path else prompt_path(f"{kind}-{mode}")
    try:
        raw = p.read_bytes()
        text = raw.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(str(p), "prompt", f"cannot read the prompt template ({exc})") from None
    lines = text.splitlines()
    if lines.count(SPLIT[0]) != 1 or lines.count(SPLIT[1]) != 1 or lines.index(SPLIT[0]) > lines.index(SPLIT[1]):
        raise ScenarioError(str(p), "prompt", f"a prompt template holds a line '{SPLIT[0]}' and, after it, a line "
                            f"'{SPLIT[1]}', each once; the text under each is that message")
    heads = [n for n, line in enumerate(lines) if line in (*SPLIT, *EXAMPLE)]
    names = [lines[n] for n in heads]
    middle = names[1:-1]
    if names[0] != SPLIT[0] or names[-1] != SPLIT[1] or middle != list(EXAMPLE) * (len(middle) // 2) or len(middle) % 2:
        raise ScenarioError(str(p), "prompt", f"the worked examples of a prompt template go between '{SPLIT[0]}' and "
                            f"'{SPLIT[1]}', each a line '{EXAMPLE[0]}' and then a line '{EXAMPLE[1]}'")
    bodies = ["\n".join(lines[a + 1:b]).strip() for a, b in zip(heads, heads[1:] + [len(lines)])]
    system, user = bodies[0], bodies[-1]
    examples = [{"role": "user" if name == EXAMPLE[0] else "assistant", "content": body}
                for name, body in zip(middle, bodies[1:-1])]
    for part in (system, user):
        t = Template(part)
        if not t.is_valid():
            raise ScenarioError(str(p), "prompt", "a '$' that starts no field; write '$$' for a dollar sign")
        bad = [f for f in t.get_identifiers() if f not in FIELDS[kind]]
        if bad:
            raise ScenarioError(str(p), "prompt", f"no field ${bad[0]} in {kind} search; its fields: "
                                f"{', '.join('$' + f for f in FIELDS[kind])}")
    if any(not m["content"] for m in examples):
        raise ScenarioError(str(p), "prompt", "a worked example's message is empty")
    return system, user, examples, hashlib.sha256(raw).hexdigest()


class LlmCore(Planner):
    """The kind-neutral part of the ``llm`` planner (see the module docstring); each kind's part
    calls :meth:`begin` at each decision and :meth:`ask` for the model's choice."""

    Params = LlmParams
    cost_columns = COST_COLUMNS
    service = True

    def __init__(self, params: LlmParams):
        super().__init__(params)
        self.replan_on_signs = params.replan_on_signs
        self.kind: str | None = None  # the kind of search it answers: known when the run starts, or at its first decision
        self.run: dict = {}
        self.transcript: list[dict] = []
        self.calls = self.tokens_in = self.tokens_out = self.invalid = self.fallbacks = 0
        self.last_failure = ""  # why the last decision that fell back did
        self.llm_s = 0.0
        self.decision = 0
        self.spent = ""
        self.dry_run = False  # set by a dry run: the first prompt is raised (FirstPrompt), nothing is called
        self._prompt: tuple[str, str, str] | None = None
        self._examples: list[dict] = []
        self._replay: list[dict] | None = None
        self._chat: Chat | None = None
        self._live = params  # the parameters the run behaves by (a replay's: its transcript's)
        if params.replay is None:
            fault = self.fault(params)
            if fault:
                raise PlannerError(f"llm: {fault[0]}: {fault[1]}")
            require_openai()
        else:  # the re-plan cadence the transcripts were made with, known before a run starts (a policy's env_kwargs)
            made = replan_on_signs(Path(params.replay), params.replay_planner)
            if len(made) == 1:
                self.replan_on_signs = made.pop()

    @classmethod
    def fault(cls, params: LlmParams, kind: str | None = None) -> tuple[str, str] | None:
        """A model to call, or transcripts to replay, must be named (a ``base_url`` that is an
        address holding no credential; a ``replay`` folder that holds transcripts); in a scenario
        of ``kind``, the mode must be one that kind takes and the prompt template must use only
        its fields."""
        if params.replay is None and not params.model.strip():
            return "model", ("name the model the server serves (e.g. model: qwen2.5-7b-instruct), or replay "
                             "transcripts (replay: DIR)")
        if params.replay is None and url_fault(params.base_url):
            return "base_url", url_fault(params.base_url)
        if params.replay is not None and not Path(params.replay).is_dir():
            return "replay", (f"{params.replay} is not a folder: replay names a results folder (or a bench folder) whose runs "
                              "were made with --transcripts")
        if params.replay is not None and not files(Path(params.replay)):
            return "replay", (f"{params.replay} holds no transcripts (transcripts/<run>.jsonl, which run --transcripts "
                              "writes): a replay would find none of its runs")
        if kind in MODES and params.mode not in MODES[kind]:
            return "mode", (f"{kind} search takes mode {' or '.join(MODES[kind])}: its choices are poses of a lattice, "
                            "not places a probability can be put on" if kind == "indirect" else
                            f"{kind} search takes mode {' or '.join(MODES[kind])}")
        if kind in FIELDS and params.replay is None and params.prompt is not None:
            try:
                load_prompt(params.prompt, kind, params.mode)
            except ScenarioError as exc:
                return "prompt", f"{exc.file}: {exc.message}"
        return None

    @classmethod
    def preflight(cls, params: LlmParams) -> tuple[str, str] | None:
        """Before a batch's first run: the ``openai`` package installed, and the endpoint answering
        (:func:`.client.preflight`); nothing for a replay, which calls nothing."""
        if params.replay is not None:
            return None
        return cls.missing(params) or look_at_endpoint(params.base_url, params.model, params.api_key_env,
                                                       "api_key_env" in params.model_fields_set)

    @classmethod
    def missing(cls, params: LlmParams) -> tuple[str, str] | None:
        """The ``openai`` package, unless the planner replays transcripts (which calls nothing)."""
        if params.replay is None and not openai_installed():
            return "name", MISSING
        return None

    @classmethod
    def inputs(cls, params: LlmParams) -> str:
        """The prompt template's bytes' hash (every shipped one of the mode, without ``prompt``),
        or the replayed transcripts' (names and hashes)."""
        if params.replay is not None:
            return "replay\0" + folder_text(Path(params.replay))
        if params.prompt is not None:
            return "prompt\0" + hashlib.sha256(Path(params.prompt).read_bytes()).hexdigest()
        return "prompts\0" + "".join(hashlib.sha256(prompt_path(f"{k}-{params.mode}").read_bytes()).hexdigest()
                                     for k in MODES if params.mode in MODES[k])

    # ---- the run ----------------------------------------------------------------------------
    def start_run(self, run: dict) -> None:
        """The run's identity (from the seat: scenario, kind, planner, goal, episode, seed, stage);
        a replay finds its transcript by it."""
        self.run = dict(run)
        if run.get("kind"):
            self.kind = str(run["kind"])
        if self.params.replay is None:
            self.transcript, self._prompt = [], None
            if self.kind:
                self.begin(self.kind)
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
        if self.kind and head.get("kind") != self.kind:
            raise PlannerError(f"replay of {where}: {found[0][1]} is the transcript of a {head.get('kind')} search, "
                               f"not of a {self.kind} one")
        try:
            # a transcript made before the rules that stop a failing model ran without them: so does its replay
            before = {"unavailable_after": 0, "max_fallback_share": 1.0}
            self._live = LlmParams(**{**before, **head["params"], "replay": self.params.replay})
        except (TypeError, ValueError) as exc:
            raise PlannerError(f"transcript {found[0][1]}: its parameters do not read ({str(exc)[:200]})") from None
        self.replan_on_signs = self._live.replan_on_signs
        self._replay = [x for x in lines[1:] if x.get("type") == "call"]
        self.transcript = [dict(head)]

    def begin(self, kind: str) -> None:
        """A decision of a ``kind`` search: the first loads that kind's prompt template and opens
        the transcript."""
        if self.kind is None:
            self.kind = kind
        elif self.kind != kind:
            raise PlannerError(f"the llm planner of a {self.kind} search was asked a {kind} decision")
        if self.params.replay is None and self._prompt is None:
            system, user, self._examples, sha = _read_prompt(self.params.prompt, kind, self.params.mode)
            self._prompt = (system, user, sha)
            self.transcript = [header(kind, self.run, self.public_params(), self._prompt[2])]
        if self.params.replay is not None and self._replay is None:
            raise PlannerError("a replay finds each run's transcript by the run (scenario, goal, episode, seed): replay "
                               "through semsearch run, bench run or a PlannerPolicy (reset after each env.reset), which "
                               "give the planner the run's identity (start_run)")

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

    def finish_run(self) -> None:
        """A replay must use its transcript up: a run that asked fewer calls went another way. A
        run more than ``max_fallback_share`` of whose decisions fell back is not the model's
        (:class:`Unavailable`)."""
        live = self._live
        if self.decision and self.fallbacks > live.max_fallback_share * self.decision:
            raise Unavailable(f"the llm planner's model failed: {self.fallbacks} of its {self.decision} decisions fell back "
                              f"(more than max_fallback_share = {live.max_fallback_share:g}); the last failure: "
                              f"{self.last_failure}")
        if self._replay is not None and self.calls < len(self._replay):
            raise PlannerError(f"replay of run {self.describe_run()}: the run ended after {self.calls} calls, and the "
                               f"transcript holds {len(self._replay)} (the run went another way: another budget or map?)")

    # ---- a decision -------------------------------------------------------------------------
    def ask(self, fields: dict, allowed, dist: np.ndarray | None, fallback: int) -> tuple[int, dict]:
        """The model's choice at this decision: one of ``allowed`` (the numbers the answer line
        offers), asked again on an invalid reply at most ``reasks`` times, then ``fallback``.
        ``dist``: the distance (m) to each choice listed by number, for the estimator, whose
        probabilities may name any of them (a place left out of the choices is still a place the
        object may be at), and which chooses among ``allowed``."""
        live = self._live
        k = self.decision
        self.decision += 1
        allowed = [int(a) for a in allowed]
        if self._replay is None:
            system, user = (Template(t).substitute(fields) for t in self._prompt[:2])
            messages = [{"role": "system", "content": system}, *self._examples, {"role": "user", "content": user}]
        else:
            messages = []
        reason, last = "", None
        keep_to = None
        if live.reply_format != "text" and self._replay is None:
            offered = allowed if live.mode == "actor" else range(len(dist))
            keep_to = constraint(live.reply_format, schema(live.mode, offered), grammar(live.mode, offered))
        for attempt in range(live.reasks + 1):
            self.check_budget()
            if attempt and self._replay is None and last is not None:  # after no reply at all (an HTTP error): the same messages again
                messages = messages + [{"role": "assistant", "content": last[:REPEAT_CHARS]},
                                       {"role": "user", "content": f"Your reply could not be used: {reason}. {fields['answer']}"}]
            if self.dry_run:
                raise FirstPrompt(messages)
            reply, messages = self.call(k, attempt, fields["observation"], messages, keep_to)
            last = reply.text
            if reply.text is None:
                choice, reason = None, reply.error or "the reply is empty"
            elif live.mode == "actor":
                parse = parse_choice if live.reply_format in ("json_schema", "json_object") else parse_number
                choice, reason = parse(reply.text, frozenset(allowed))
            else:
                choice, reason = parse_probabilities(reply.text, range(len(dist)))  # any choice listed; chosen among allowed
            self.log_call(k, attempt, fields["observation"], messages, reply, choice, reason)
            if choice is not None:
                pick = choice if live.mode == "actor" else by_expected_cost(choice, dist, allowed)
                return pick, {"attempts": attempt + 1}
            self.invalid += 1
        self.fallbacks += 1
        self.last_failure = reason
        self.transcript.append({"type": "fallback", "decision": k, "choice": fallback, "reason": reason})
        if live.unavailable_after and self.fallbacks == self.decision == live.unavailable_after:
            raise Unavailable(f"the llm planner's model failed: every call of its first {self.decision} decisions was "
                              f"invalid ({self.invalid} calls; the last: {reason})")
        return fallback, {"fallback": True}

    def check_budget(self) -> None:
        live = self._live
        if self.calls >= live.max_calls:
            self.spent = f"the llm planner made max_calls = {live.max_calls} calls"
        elif live.max_run_tokens is not None and self.tokens_in + self.tokens_out >= live.max_run_tokens:
            self.spent = f"the llm planner used max_run_tokens = {live.max_run_tokens} tokens"
        if self.spent:
            raise BudgetSpent(self.spent)

    def call(self, k: int, attempt: int, obs: str, messages: list, keep_to: dict | None = None) -> tuple[Reply, list]:
        """One call to the model (or, in a replay, the transcript's call ``attempt`` of decision
        ``k``, its observation checked against this run's); ``keep_to``: the request's fields
        that constrain the reply (:func:`.client.constraint`)."""
        if self._replay is None:
            if self._chat is None:
                live = self._live
                self._chat = Chat(live.base_url, live.model, live.api_key_env, live.temperature, live.max_tokens,
                                  live.timeout_s, live.retries, live.max_concurrent, live.seed)
            reply = self._chat.ask(messages, keep_to)
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
                                "tokens_out": reply.tokens_out, "latency_s": round(reply.latency_s, 6), "model": reply.model,
                                "temperature": self._live.temperature, "seed": self._live.seed,
                                "reply_format": self._live.reply_format})


def by_expected_cost(p: dict[int, float], dist: np.ndarray, allowed: list[int]) -> int:
    """The choice of least expected cost among ``allowed`` (see the module docstring)."""
    idx = np.asarray(allowed, np.int64)
    prob = np.array([p.get(int(i), 0.0) for i in idx])
    if prob.sum() > 1.0:
        prob /= prob.sum()
    d = np.asarray(dist, float)[idx]
    cost = d + (1.0 - prob) * (d + d.mean())
    return int(idx[np.argmin(cost)])


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
