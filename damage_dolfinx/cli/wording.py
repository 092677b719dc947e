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
    ``k = 1e-310 underflows``, ``k[1] must be``, from the one check of that argument,
    core.validation) starts with its flag (``--k``, ``--k (value 2)``)."""
    import re
    from damage_dolfinx.core.validation import ARGUMENTS
    for api, flag in _FLAGS:
        message = message.replace(api, flag)
    head = re.match(r"(?:(damage-dolfinx: \w+: ))?(\w+)(?:\[(\d+)\])?( must | = )", message)
    if head and head.group(2) in ARGUMENTS and head.group(2) not in ("comm", "on_step"):
        flag = "--" + head.group(2).replace("_", "-")
        if head.group(3) is not None:  # one value of a list: k[1] is the second value of --k
            flag += f" (value {int(head.group(3)) + 1})"
        message = message[:head.start(2)] + flag + message[head.start(4):]
    return message
