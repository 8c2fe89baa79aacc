"""Language models as planners: ``llm``, on any OpenAI-compatible endpoint, in door, object and
indirect search, with transcripts that replay offline and costs on every row. See :mod:`.planner`
(the registered planner), :mod:`.core` (asking, re-asking, the budget, replay), :mod:`.doors`,
:mod:`.objects` and :mod:`.indirect` (what each kind shows the model), :mod:`.client` (the
endpoint), :mod:`.replies` (reading a reply) and :mod:`.transcript` (the transcript schema), and
docs/llm.md."""

from .core import FIELDS, FirstPrompt, LlmParams, load_prompt
from .doors import observation
from .planner import LlmPlanner

__all__ = ["FIELDS", "FirstPrompt", "LlmParams", "LlmPlanner", "load_prompt", "observation"]
