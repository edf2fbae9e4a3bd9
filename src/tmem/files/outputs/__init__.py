"""Output directories and files: when tmem may write or replace them, and how it survives interruptions.

Every command that writes (``tmem run``, ``tmem paper``, ``tmem animate``,
``tmem sweep``, ``tmem plot``, ``tmem view``, ``tmem export``) goes through this package:

* :mod:`tmem.files.outputs.manifest`: the manifest, and which directory a command
  may write (the rule below);
* :mod:`tmem.files.outputs.digests`: the digest of each file written, so that only what is
  still as tmem wrote it is ever replaced;
* :mod:`tmem.files.outputs.names`: temporary names, the lock their writer holds, what killed
  processes left, and where derived files go;
* :mod:`tmem.files.outputs.replace`: directories and files written under a
  temporary name and renamed into place when complete;
* :mod:`tmem.files.outputs.update`: files written again into an existing output
  all at once (``tmem plot`` into a run directory);
* :mod:`tmem.files.outputs.locking`: the locks of a directory a sweep writes into;
* :mod:`tmem.files.outputs.signals`: SIGTERM as Ctrl-C, and signals held back while
  an output is renamed into place.

The rule for output directories
-------------------------------
Each command marks the directory it writes with ``.tmem-output.json``, a
manifest naming the command and (for ``run``, ``paper``, ``plot`` and ``export``) every
file it wrote, with its SHA-256 (:mod:`tmem.files.outputs.digests`).  A command writes to ``--out DIR`` only when:

1. DIR does not exist, or is empty: it is created;
2. DIR holds an output of the *same* command (its manifest names that
   command), nothing the manifest does not list, and every file it lists
   still as the command wrote it (its digest): ``tmem run``,
   ``tmem paper``, ``tmem plot --out`` and ``tmem export --to csv`` replace it whole;
   ``tmem sweep`` resumes it, and only if it holds the same sweep (it never replaces one).

Anything else is refused with one line that says what is there: another
command's output, an output with files added to it (a note of the user's),
an output whose files were changed (notes written into ``summary.json``),
files that are not marked as a tmem output.  Files added to or changed in an output are
never deleted, replaced or carried over.  A manifest of an earlier tmem keeps no
digests: its files count as tmem's while none was modified after the manifest.
The current directory and the directories containing it, symbolic
links and files are never output directories, for any command.

Derived files (``tmem view``, ``tmem animate``, ``tmem export``) go beside the run
directory by default, never into it (:func:`~tmem.files.outputs.names.beside`): ``NAME.html``,
``NAME.gif``, ``NAME.mcap``, ``NAME-crazyswarm/`` for a run directory ``NAME``.  Such a file is
replaced only if it is a regular file that tmem wrote (its mark: a GIF's comment
``written by tmem animate``, the same in MP4 metadata, MCAP's and HTML's own); a FIFO, a device or
a link is refused, and nothing of it is read.

Interruptions
-------------
A directory or file is written inside a hidden temporary directory next to its
destination, ``.NAME.tmem-partial-PID-RANDOM``, and renamed into place only when complete;
the old output is moved aside and removed in the same step, with Ctrl-C and SIGTERM held back
until it is done.  So Ctrl-C, SIGTERM (handled like Ctrl-C: :func:`handle_termination`) or an
error leave the destination as it was.  While it writes, the writer holds the operating
system's lock (``flock``) on ``.tmem-writing`` inside the temporary directory.  A process killed
outright (SIGKILL, power cut) leaves the temporary directory behind, its lock free; the next
command writing into the same folder takes the lock and removes it (:func:`remove_leftovers`).
Whether a writer still works is told by its lock alone, never by its process id: a tmem in
another container or process-id namespace is seen to be writing.  Nothing else is ever removed:
a name that does not match exactly, a temporary name without the lock file (an earlier tmem's),
one whose lock is held.

Two commands at once
--------------------
A sweep, which writes into its directory for a long time, holds ``.NAME.tmem-lock`` beside its
directory from before it looks at the directory (:func:`lock_beside`), and ``.tmem-lock`` inside
it once it exists (:func:`lock`): locks held by the operating system for as long as the process
lives, with the holder's process id written in them.  A second sweep into the same directory,
started even at the same instant, is refused in one line naming that process; once the holder
ends, even killed, the next one takes the lock.
"""

from tmem.files.outputs.locking import lock, lock_beside
from tmem.files.outputs.manifest import MANIFEST, OutputError, check_directory
from tmem.files.outputs.names import beside, one_line, partial_name, remove_leftovers
from tmem.files.outputs.replace import ANIMATE_MARK, check_file, create_directory, mark_directory, replace_directory, replace_file, write_atomically
from tmem.files.outputs.signals import handle_termination, ignore_interrupts
from tmem.files.outputs.update import update_files

__all__ = [
    "ANIMATE_MARK",
    "MANIFEST",
    "OutputError",
    "beside",
    "check_directory",
    "check_file",
    "create_directory",
    "handle_termination",
    "ignore_interrupts",
    "lock",
    "lock_beside",
    "mark_directory",
    "one_line",
    "partial_name",
    "remove_leftovers",
    "replace_directory",
    "replace_file",
    "update_files",
    "write_atomically",
]
