"""The API's messages in the command line's words: the flags for the arguments they name."""

#: API wording -> command-line wording, applied in this order (the command line's refusal already
#: states k_max: the API's way to ask for it before a run is left out there)
_FLAGS = ((" (problem.k_max() gives k_max before the run)", ""), ("restart=True", "--restart"), ("overwrite=True", "--overwrite"),
          ("allow_unstable=True", "--allow-unstable"), ("allow_long=True", "--allow-long"),
          ("another out folder", "another --out"), ("checkpoint_seconds", "--checkpoint-seconds"),
          ("checkpoint_every", "--checkpoint-every"), ("write_every", "--write-every"),
          ("a larger T ", "a larger --T "))


def for_command_line(message: str) -> str:
    """A message of the API with the command line's flags for the arguments it names: the
    phrases of _FLAGS, and a refusal that starts with an argument's name (``k must be > 0``,
    from the one check of that argument, core.validation) starts with its flag (``--k``)."""
    import re
    from damage_dolfinx.core.validation import ARGUMENTS
    for api, flag in _FLAGS:
        message = message.replace(api, flag)
    head = re.match(r"(?:(damage-dolfinx: \w+: ))?(\w+)( must )", message)
    if head and head.group(2) in ARGUMENTS and head.group(2) not in ("comm", "on_step"):
        start, end = head.span(2)
        message = message[:start] + "--" + head.group(2).replace("_", "-") + message[end:]
    return message
