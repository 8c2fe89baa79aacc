"""Language models as planners: ``llm`` (door search), on any OpenAI-compatible endpoint, with
transcripts that replay offline and costs on every row. See :mod:`.doors` (the planner),
:mod:`.client` (the endpoint), :mod:`.replies` (reading a reply) and :mod:`.transcript` (the
transcript schema), and docs/llm.md."""

from .doors import FIELDS, FirstPrompt, LlmParams, LlmPlanner, load_prompt, observation

__all__ = ["FIELDS", "FirstPrompt", "LlmParams", "LlmPlanner", "load_prompt", "observation"]
