#!/usr/bin/env python3
"""A scripted OpenAI-compatible chat-completions server for ReactHuman's tests and benchmark.

Listens on 127.0.0.1 (port 0 = any free port; the chosen port is printed as the first line
of stdout: "PORT <n>"), exits by itself after --lifetime seconds, and is otherwise stopped
by its PID. Requests to POST .../chat/completions are answered by the next entry of
--script (separated by ";"), then by --then for every later request:

  fenced | prose | bare   a plan as a ```json fenced block, inside prose, or bare JSON
  cycle                   fenced, prose, bare in turn (by request number)
  refusal                 message.content null, message.refusal set
  select:<json>           the JSON text as the answer (the planner's selection)
  429 | 429ra=<s>         rate limited, without / with a Retry-After header (seconds)
  500 | 502 | 503         server error
  401                     invalid key; the body echoes the Authorization header
  hang                    answer only after --hang seconds (past the client's timeout)
  drop                    close the connection without answering
  malformed               HTTP 200 with a body that is not JSON
  empty                   HTTP 200 with "choices": []
  huge:<MB>               the prose answer followed by MB megabytes of padding text

--delay adds that many seconds before every answer (the benchmark's 200 ms server).
--log FILE appends one JSON line per request: n, time, behaviour, authorization header,
model, number of images, the first user text, temperature.
"""

import argparse
import json
import os
import socket
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

PLAN = {
    "intent": "catch the object with both hands in front of the chest",
    "object_identified": "a small object",
    "confidence": 0.7,
    "walking_cmd": [0.0, 0.0, 0.0],
    "walking_duration": 0.0,
    "keyframes": [
        {"t": 0.2, "left_hand": [0.40, 0.12, 0.25], "right_hand": [0.40, -0.12, 0.25], "knee_bend": 0.1},
        {"t": 0.4, "left_hand": [0.50, 0.10, 0.30], "right_hand": [0.50, -0.10, 0.30], "knee_bend": 0.1},
    ],
}


def answer_text(kind):
    plan = json.dumps(PLAN)
    if kind == "fenced":
        return "```json\n" + plan + "\n```"
    if kind == "prose":
        return "The object is light and falls toward me, so I will catch it. My plan: " + plan + " That is all."
    return plan


class State:
    def __init__(self, script, then, log):
        self.script = script
        self.then = then
        self.lock = threading.Lock()
        self.n = 0
        self.log = log


def make_handler(state, args):
    class Handler(BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"

        def log_message(self, *a):
            pass

        def send_json(self, status, obj, headers=None, raw=None):
            body = raw if raw is not None else json.dumps(obj).encode()
            self.send_response(status)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(body)))
            for k, v in (headers or {}).items():
                self.send_header(k, v)
            self.end_headers()
            self.wfile.write(body)
            self.wfile.flush()

        def do_GET(self):
            self.send_json(200, {"object": "list", "data": [{"id": "test-model", "object": "model"}]})

        def do_POST(self):
            length = int(self.headers.get("Content-Length") or 0)
            raw = self.rfile.read(length)
            try:
                req = json.loads(raw)
            except ValueError:
                req = {}
            with state.lock:
                n = state.n
                state.n += 1
                kind = state.script[n] if n < len(state.script) else state.then
            if kind == "cycle":
                kind = ["fenced", "prose", "bare"][n % 3]
            images = 0
            first_text = None
            for m in req.get("messages", []):
                c = m.get("content")
                if isinstance(c, list):
                    for part in c:
                        if part.get("type") == "image_url":
                            images += 1
                        elif part.get("type") == "text" and first_text is None and m.get("role") == "user":
                            first_text = part.get("text")
                elif m.get("role") == "user" and first_text is None:
                    first_text = c
            if state.log:
                entry = {
                    "n": n,
                    "time": time.time(),
                    "behaviour": kind,
                    "authorization": self.headers.get("Authorization"),
                    "model": req.get("model"),
                    "images": images,
                    "first_user_text": first_text,
                    "temperature": req.get("temperature"),
                    "messages": len(req.get("messages", [])),
                }
                with state.lock:
                    with open(state.log, "a") as f:
                        f.write(json.dumps(entry) + "\n")
            if args.delay > 0:
                time.sleep(args.delay)
            usage = {"prompt_tokens": 1000, "completion_tokens": 100, "total_tokens": 1100}
            try:
                if kind in ("fenced", "prose", "bare"):
                    self.send_json(200, {
                        "id": "chatcmpl-%d" % n, "object": "chat.completion", "model": req.get("model"),
                        "choices": [{"index": 0, "finish_reason": "stop",
                                     "message": {"role": "assistant", "content": answer_text(kind)}}],
                        "usage": usage,
                    })
                elif kind.startswith("huge:"):
                    pad = "word " * (int(float(kind[len("huge:"):]) * 1_000_000) // 5)
                    self.send_json(200, {
                        "choices": [{"index": 0, "finish_reason": "length",
                                     "message": {"role": "assistant", "content": answer_text("prose") + " " + pad}}],
                        "usage": usage,
                    })
                elif kind.startswith("select:"):
                    self.send_json(200, {
                        "choices": [{"index": 0, "finish_reason": "stop",
                                     "message": {"role": "assistant", "content": kind[len("select:"):]}}],
                        "usage": usage,
                    })
                elif kind == "refusal":
                    self.send_json(200, {
                        "choices": [{"index": 0, "finish_reason": "stop",
                                     "message": {"role": "assistant", "content": None,
                                                 "refusal": "I'm sorry, I can't help with that."}}],
                        "usage": usage,
                    })
                elif kind == "429":
                    self.send_json(429, {"error": {"message": "Rate limit reached", "type": "rate_limit"}})
                elif kind.startswith("429ra="):
                    self.send_json(429, {"error": {"message": "Rate limit reached"}},
                                   headers={"Retry-After": kind.split("=", 1)[1]})
                elif kind in ("500", "502", "503"):
                    self.send_json(int(kind), {"error": {"message": "upstream trouble %s" % kind}})
                elif kind == "401":
                    self.send_json(401, {"error": {"message": "Incorrect API key provided: %s" %
                                                   self.headers.get("Authorization")}})
                elif kind == "hang":
                    time.sleep(args.hang)
                    self.send_json(200, {"choices": [{"message": {"content": answer_text("bare")}}]})
                elif kind == "drop":
                    self.close_connection = True
                    self.connection.shutdown(socket.SHUT_RDWR)
                    self.connection.close()
                elif kind == "malformed":
                    self.send_json(200, None, raw=b'{"choices": [{"message": {"content": "trunc')
                elif kind == "empty":
                    self.send_json(200, {"choices": [], "usage": usage})
                else:
                    self.send_json(400, {"error": {"message": "unknown scripted behaviour " + kind}})
            except (BrokenPipeError, ConnectionResetError, OSError):
                self.close_connection = True

    return Handler


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--script", default="")
    ap.add_argument("--then", default="cycle")
    ap.add_argument("--delay", type=float, default=0.0)
    ap.add_argument("--hang", type=float, default=5.0)
    ap.add_argument("--lifetime", type=float, default=300.0)
    ap.add_argument("--log", default=None)
    args = ap.parse_args()
    script = [s for s in args.script.split(";") if s]
    state = State(script, args.then, args.log)
    server = ThreadingHTTPServer(("127.0.0.1", args.port), make_handler(state, args))
    server.daemon_threads = True
    server.request_queue_size = 128
    print("PORT %d" % server.server_address[1], flush=True)
    timer = threading.Timer(args.lifetime, lambda: os._exit(0))
    timer.daemon = True
    timer.start()
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    sys.exit(0)


if __name__ == "__main__":
    main()
