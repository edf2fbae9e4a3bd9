"""Output directories and files: when tmem may write or replace them, and how it survives interruptions.

Every command that writes (``tmem run``, ``tmem paper``, ``tmem animate``,
``tmem sweep``, ``tmem plot``) goes through this package:

* :mod:`tmem.files.outputs.manifest`: the manifest, and which directory a command
  may write (the rule below);
* :mod:`tmem.files.outputs.names`: temporary names, and what killed processes left;
* :mod:`tmem.files.outputs.replace`: directories and files written under a
  temporary name and renamed into place when complete;
* :mod:`tmem.files.outputs.update`: files written again into an existing output
  all at once (``tmem plot`` into a run directory);
* :mod:`tmem.files.outputs.locking`: the lock of a directory a sweep writes into;
* :mod:`tmem.files.outputs.signals`: SIGTERM as Ctrl-C, and signals held back while
  an output is renamed into place.

The rule for output directories
-------------------------------
Each command marks the directory it writes with ``.tmem-output.json``, a
manifest naming the command and (for ``run``, ``paper`` and ``plot``) every
file it wrote.  A command writes to ``--out DIR`` only when:

1. DIR does not exist, or is empty: it is created;
2. DIR holds an output of the *same* command (its manifest names that
   command) and nothing the manifest does not list: ``tmem run``,
   ``tmem paper`` and ``tmem plot --out`` replace it whole; ``tmem sweep`` resumes it, and only if it
   holds the same sweep (it never replaces one).

Anything else is refused with one line that says what is there: another
command's output, an output with files added to it (an ``animation.gif``
that ``tmem animate`` wrote into a run directory, a note of the user's),
files that are not marked as a tmem output.  Files added to an output are
never deleted and never carried over: rerunning into a run directory that
holds an animation is refused, since the animation would no longer show the
run.  The current directory and the directories containing it, symbolic
links and files are never output directories, for any command.  ``tmem
animate`` replaces an existing file only if it wrote it (its GIFs carry the
comment ``written by tmem animate``, its MP4s the same metadata).

Interruptions
-------------
A directory or file is written under a hidden temporary name next to its
destination, ``.NAME.tmem-partial-PID-RANDOM`` (PID: the writing process),
and renamed into place only when complete; the old output is moved aside and
removed in the same step, with Ctrl-C and SIGTERM held back until it is done.
So Ctrl-C, SIGTERM (handled like Ctrl-C: :func:`handle_termination`) or an
error leave the destination as it was.  A process killed outright (SIGKILL,
power cut) leaves its temporary name behind; the next command writing into
the same folder recognises it by the name and by its process being gone from
this machine, and removes it (:func:`remove_leftovers`).  Nothing else is ever
removed: a name that does not match exactly, or whose process still runs, is
left alone.

Two commands at once
--------------------
A sweep, which writes into its directory for a long time, holds
``.tmem-lock`` there (:func:`lock`): a lock held by the operating system for
as long as the process lives, with the holder's process id written in it.  A
second sweep into the same directory is refused in one line naming that
process; once the holder ends, even killed, the next one takes the lock.
"""

from tmem.files.outputs.locking import lock
from tmem.files.outputs.manifest import MANIFEST, OutputError, check_directory
from tmem.files.outputs.names import partial_name, remove_leftovers
from tmem.files.outputs.replace import ANIMATE_MARK, check_file, create_directory, mark_directory, replace_directory, replace_file, write_atomically
from tmem.files.outputs.signals import handle_termination, ignore_interrupts
from tmem.files.outputs.update import update_files

__all__ = [
    "ANIMATE_MARK",
    "MANIFEST",
    "OutputError",
    "check_directory",
    "check_file",
    "create_directory",
    "handle_termination",
    "ignore_interrupts",
    "lock",
    "mark_directory",
    "partial_name",
    "remove_leftovers",
    "replace_directory",
    "replace_file",
    "update_files",
    "write_atomically",
]
