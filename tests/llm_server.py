"""An OpenAI-compatible chat-completions server on loopback, for the llm planner's tests: a real
HTTP server (``http.server``, one thread per request) whose replies a test scripts.

    with ChatServer(script) as srv:          # script(request: dict, n: int) -> Answer
        base_url = srv.base_url              # http://127.0.0.1:<port>/v1

``Answer(text)`` replies with a chat completion holding ``text`` (and token counts);
``Answer(status=500)`` with that HTTP status; ``Answer(raw=b"...")`` with those bytes as the body;
``Answer(delay=s)`` after ``s`` seconds (a server that hangs). Every request's body and
``Authorization`` header are kept (``requests``, ``keys``).

``GET /v1/models`` lists ``models`` (None: 404, a server that lists none); ``key``: every request
without ``Authorization: Bearer <key>`` is answered 401; ``status``: every request (GET and POST)
is answered with that HTTP status (a server that is down behind its proxy). ``gets`` counts the
GET requests (the planner's look at the endpoint before a batch).
"""

from __future__ import annotations

import json
import re
import threading
import time
from dataclasses import dataclass
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer


@dataclass
class Answer:
    text: str | None = None
    status: int = 200
    raw: bytes | None = None
    delay: float = 0.0
    tokens_in: int = 100
    tokens_out: int = 3
    model: str = "scripted-1"


def decision_text(messages: list[dict]) -> str:
    """The decision a request asks about: its last user message that is not a re-ask (a prompt's
    worked examples come before it, the replies and re-asks after)."""
    return next(m["content"] for m in reversed(messages) if m["role"] == "user"
                and "Your reply could not be used" not in m["content"])


def first_target(request: dict, n: int) -> Answer:
    """The "nearest target" model: the number of the first choice the decision lists."""
    text = decision_text(request["messages"])
    m = re.search(r"^\[(\d+)\]", text, re.M)
    return Answer(m.group(1) if m else "0")


class ChatServer:
    def __init__(self, script=first_target, models=None, key: str | None = None, status: int | None = None):
        self.script, self.requests, self.keys = script, [], []
        self.models, self.key, self.status, self.gets = models, key, status, []
        self.lock = threading.Lock()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):  # quiet
                pass

            def reply(self, status: int, payload: bytes) -> None:
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(payload)))
                    self.end_headers()
                    self.wfile.write(payload)
                except (BrokenPipeError, ConnectionResetError):  # the client gave up (a timeout)
                    pass

            def refused(self) -> bool:
                """Answered already: a scripted status for every request, or a key missing."""
                if server.status is not None:
                    self.reply(server.status, json.dumps({"error": {"message": "scripted", "type": "server_error"}}).encode())
                    return True
                if server.key is not None and self.headers.get("Authorization", "") != f"Bearer {server.key}":
                    self.reply(401, json.dumps({"error": {"message": "Incorrect API key provided", "type":
                                                          "invalid_request_error", "code": "invalid_api_key"}}).encode())
                    return True
                return False

            def do_GET(self):
                with server.lock:
                    server.gets.append(self.path)
                if self.refused():
                    return
                if self.path.rstrip("/") == "/v1/models" and server.models is not None:
                    self.reply(200, json.dumps({"object": "list", "data": [{"id": m, "object": "model", "created": 0,
                                                                            "owned_by": "test"} for m in server.models]}).encode())
                else:
                    self.reply(404, json.dumps({"error": {"message": f"no route {self.path}"}}).encode())

            def do_POST(self):
                if not self.path.startswith("/v1/"):  # a base_url without /v1: what vLLM and llama.cpp answer
                    self.rfile.read(int(self.headers.get("Content-Length", 0)))
                    self.reply(404, json.dumps({"detail": "Not Found"}).encode())
                    return
                if self.refused():
                    self.rfile.read(int(self.headers.get("Content-Length", 0)))
                    return
                length = int(self.headers.get("Content-Length", 0))
                body = json.loads(self.rfile.read(length) or b"{}")
                with server.lock:
                    n = len(server.requests)
                    server.requests.append(body)
                    server.keys.append(self.headers.get("Authorization", ""))
                ans = server.script(body, n)
                if ans.delay:
                    time.sleep(ans.delay)
                if ans.raw is not None:
                    payload, status = ans.raw, ans.status
                elif ans.status != 200:
                    payload, status = json.dumps({"error": {"message": "scripted", "type": "server_error"}}).encode(), ans.status
                else:
                    payload, status = json.dumps({
                        "id": f"chatcmpl-{n}", "object": "chat.completion", "created": 0, "model": ans.model,
                        "choices": [{"index": 0, "message": {"role": "assistant", "content": ans.text},
                                     "finish_reason": "stop"}],
                        "usage": {"prompt_tokens": ans.tokens_in, "completion_tokens": ans.tokens_out,
                                  "total_tokens": ans.tokens_in + ans.tokens_out}}).encode(), 200
                self.reply(status, payload)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.base_url = f"http://127.0.0.1:{self.httpd.server_address[1]}/v1"

    def __enter__(self) -> "ChatServer":
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()
