"""NumPy ``.npz`` files read with bounds: one array at a time, none larger than the file that holds it.

``np.load`` reads an array's header and allocates what it declares before it reads a byte of the
data: a damaged or foreign file declaring 2^31 doubles asks for 16 GiB.  :class:`NpzArrays` opens
the file (a regular file only: a FIFO or a device is never opened for reading), lists its arrays,
and reads one only when asked, after checking that the bytes its header declares are the bytes
the file holds for it: an array stored uncompressed (as ``np.savez`` writes them), of a plain
type (no Python objects), its data exactly the rest of its entry.  So a reader can look at one
small array first (a checkpoint's ``meta``) and refuse the file before any other is read.
"""

from __future__ import annotations

import math
import os
import stat
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["NpzArrays"]


class NpzArrays:
    """The arrays of an ``.npz`` file, each read on demand within the bytes the file holds for it.

    Use as a context manager; :attr:`names` lists the arrays, :meth:`read` reads one.

    Parameters
    ----------
    path : str or Path
        The file.

    Raises
    ------
    ValueError
        If ``path`` is not a regular file, or not a ZIP archive.
    OSError
        If it cannot be opened.
    """

    def __init__(self, path: str | Path) -> None:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        handle = os.fdopen(fd, "rb")
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                raise ValueError("not a regular file")
            self.size = info.st_size
            self._zip = zipfile.ZipFile(handle)
        except BaseException:
            handle.close()
            raise
        self._handle = handle
        self.names = [n.removesuffix(".npy") for n in self._zip.namelist() if n.endswith(".npy")]

    def __enter__(self) -> "NpzArrays":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the file."""
        self._zip.close()
        self._handle.close()

    def read(self, name: str) -> np.ndarray:
        """The array ``name``, read only if its header declares exactly the bytes its entry holds.

        Parameters
        ----------
        name : str
            One of :attr:`names`.

        Raises
        ------
        ValueError
            If the entry is compressed, of Python objects, declares more or fewer bytes than it
            holds, or is cut short; KeyError if there is no such array.
        """
        entry = self._zip.getinfo(f"{name}.npy")
        if entry.compress_type != zipfile.ZIP_STORED or entry.file_size > self.size:
            raise ValueError(f"{name}: not stored as np.savez stores arrays")
        with self._zip.open(entry) as f:
            version = np.lib.format.read_magic(f)
            read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, fortran, dtype = read_header(f)
            if dtype.hasobject:
                raise ValueError(f"{name}: holds Python objects")
            count = math.prod(shape)
            declared = count * dtype.itemsize
            if declared != entry.file_size - f.tell():
                raise ValueError(f"{name}: its header declares {declared} bytes, its entry holds {entry.file_size - f.tell()}")
            data = f.read(declared)
        if len(data) != declared:
            raise ValueError(f"{name}: cut short")
        values = np.frombuffer(data, dtype=dtype, count=count)
        return values.reshape(shape, order="F" if fortran else "C").copy()
