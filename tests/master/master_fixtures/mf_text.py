"""Test fixture: texts. `text` is `prefix` followed by the number of steps taken; `length` is
the number of characters of the String input `text_in` (direct feedthrough); `shout` is
`text_in` in capitals, with its commas and quotes kept (CSV quoting)."""
from neighbor_fmu_support import NeighborSlave


class _TextModel:
    def get_state(self):
        return None

    def set_state(self, state):
        pass


class MfText(NeighborSlave):
    description = "Test text block: a String output counting steps, a String input and its length"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("prefix", "n=", None, "Text before the step count", kind=str)
        self.input("text_in", "", None, "A text", kind=str)
        self.output("text", lambda: f"{self.values['prefix']}{self.values['n_steps']}", None,
                    "prefix and the steps taken", kind=str)
        self.output("length", lambda: len(self.values["text_in"]), None, "Characters in text_in", kind=int,
                    depends_on=["text_in"])
        self.output("shout", lambda: self.values["text_in"].upper(), None, "text_in in capitals", kind=str,
                    depends_on=["text_in"])
        self.values["n_steps"] = 0

    def build_model(self):
        return _TextModel()

    def do_step(self, current_time, step_size):
        self.values["n_steps"] += 1
        return True
