"""Runs the inspect CLI (`python inspect_offline.py eval ...` = `inspect eval ...`) with no
network. inspect's mock model reports token usage counted with tiktoken's o200k_base
encoding, which tiktoken downloads on first use; when that file is not in tiktoken's
cache, the mock model counts text tokens as characters / 4 instead (its documented
override point, `ModelAPI.count_text_tokens`). Only the mock's reported usage changes;
prompts, answers and scores do not."""

import sys


def offline_tokens() -> bool:
    try:
        import tiktoken

        tiktoken.get_encoding("o200k_base")
        return False
    except Exception:  # not cached and no network
        from inspect_ai.model._providers.mockllm import MockLLM

        async def count_text_tokens(self, text: str) -> int:
            return max(1, len(text) // 4)

        MockLLM.count_text_tokens = count_text_tokens
        return True


if __name__ == "__main__":
    if offline_tokens():
        print("inspect_offline: tiktoken's o200k_base is not available; the mock model counts characters / 4", file=sys.stderr)
    from inspect_ai._cli.main import main

    sys.argv[0] = "inspect"
    main()
