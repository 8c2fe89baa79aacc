"""An OpenAI-compatible chat-completions server on loopback, for the llm planner's tests: a real
HTTP server (``http.server``, one thread per request) whose replies a test scripts.

    with ChatServer(script) as srv:          # script(request: dict, n: int) -> Answer
        base_url = srv.base_url              # http://127.0.0.1:<port>/v1

``Answer(text)`` replies with a chat completion holding ``text`` (and token counts);
``Answer(status=500)`` with that HTTP status; ``Answer(raw=b"...")`` with those bytes as the body;
``Answer(delay=s)`` after ``s`` seconds (a server that hangs). Every request's body and
``Authorization`` header are kept (``requests``, ``keys``).
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


def first_target(request: dict, n: int) -> Answer:
    """The "nearest target" model: the number of the first choice the last user message lists."""
    text = request["messages"][-1]["content"]
    if "Your reply could not be used" in text:
        text = next(m["content"] for m in request["messages"] if m["role"] == "user")
    m = re.search(r"^\[(\d+)\]", text, re.M)
    return Answer(m.group(1) if m else "0")


class ChatServer:
    def __init__(self, script=first_target):
        self.script, self.requests, self.keys = script, [], []
        self.lock = threading.Lock()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):  # quiet
                pass

            def do_POST(self):
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
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(payload)))
                    self.end_headers()
                    self.wfile.write(payload)
                except (BrokenPipeError, ConnectionResetError):  # the client gave up (a timeout)
                    pass

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
