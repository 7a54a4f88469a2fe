"""The models a service answers about: the registered mechanisms by name, and uploaded ones in a content-addressed
store.

An upload is a set of files ``{name: bytes}`` (a closure spec and its model file, a Gepetto URDF + YAML pair, an
MJCF or SDF file alone), or one archive of them (zip, tar: :meth:`Store.unpack`), read in memory by pkm's loaders (:func:`pkm.core.formats.load.load_texts`): no uploaded name
reaches the file system. A Gepetto pair's ``robot.urdf`` is named after its folder, as :func:`pkm.load` names it
(``battobot_6d``, not ``robot``): the folder an archive's files are in (else the archive's own name), or the
``folder`` an upload of files states (the Python client sends the files' folder). Its id is a hash of the names and
contents, and of that folder where it names the mechanism (the same files give the same id); with a
folder (``pkm serve --store DIR``) each upload is kept as its blobs (named by their own hashes) and a manifest, and
read back when the service starts again. Mechanisms are built once and kept in memory.
"""

from __future__ import annotations

import hashlib
import json
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, SpecError, UnknownNameError

#: Limits of an upload: files, bytes per file, bytes in all.
MAX_FILES = 8
MAX_FILE_BYTES = 8 * 2**20
MAX_UPLOAD_BYTES = 16 * 2**20


@dataclass(frozen=True)
class Entry:
    """A model the service knows: ``id`` (a registered name, or an upload's hash), ``kind`` (``"registered"`` or
    ``"uploaded"``), ``files`` (an upload's file names and sizes)."""

    id: str
    kind: str
    name: str
    files: dict[str, int]


def upload_id(files: dict[str, bytes], folder: str | None = None) -> str:
    """The id of an upload: the first 20 hex digits of SHA-256 over its names and contents, in name order, and the
    folder that names it (:func:`naming_folder`), if any."""
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0" + hashlib.sha256(files[name]).digest())
    if folder is not None:
        h.update(b"\0folder\0" + folder.encode())
    return h.hexdigest()[:20]


def _plain_name(name: object) -> bool:
    return isinstance(name, str) and bool(name) and len(name) <= 200 and not any(c in name for c in "/\\\0") \
        and name not in (".", "..")


def naming_folder(files: dict[str, bytes], folder: str | None) -> str | None:
    """``folder`` where it names the upload's mechanism (Gepetto's ``robot.urdf``:
    :func:`pkm.core.formats.load.gepetto_name`), else None (it changes nothing: not in the id either).

    Raises:
        InvalidInputError: a folder that is not a plain name.
    """
    from pkm.core.formats.load import GEPETTO_URDF

    if folder is None or folder == "" or GEPETTO_URDF not in files:
        return None
    if not _plain_name(folder):
        raise InvalidInputError("folder", "a plain name (no path)", folder)
    return folder


class Store:
    """The registered mechanisms and the uploads (see the module doc); thread-safe.

    Args:
        folder: Where uploads are kept across restarts (None: in memory only).
    """

    def __init__(self, folder: str | Path | None = None):
        from pkm.mechanisms import REGISTRY

        self.folder = None if folder is None else Path(folder)
        self._lock = threading.Lock()
        self._mechanisms: dict[str, Mechanism] = {}
        self._uploads: dict[str, Entry] = {}
        self._files: dict[str, dict[str, bytes]] = {}
        self._kernels: dict[str, Any] = {}
        self.registered = sorted(REGISTRY)
        if self.folder is not None:
            self.folder.mkdir(parents=True, exist_ok=True)
            for manifest in sorted(self.folder.glob("*/manifest.json")):
                try:
                    kept = json.loads(manifest.read_text())
                    files = {n: (manifest.parent / f"{h}.blob").read_bytes() for n, h in kept["files"].items()}
                    self.add(files, persist=False, folder=kept.get("folder"))
                except (OSError, ValueError, KeyError, SpecError, InvalidInputError):
                    continue  # (a damaged entry is skipped, never served)

    def entries(self) -> list[Entry]:
        """Every model: the registered ones, then the uploads."""
        with self._lock:
            uploads = list(self._uploads.values())
        return [Entry(n, "registered", n, {}) for n in self.registered] + uploads

    @staticmethod
    def unpack(files: dict[str, bytes]) -> tuple[dict[str, bytes], str | None]:
        """An upload of one archive (``.zip``, ``.tar``, ``.tar.gz``, ``.tgz``) as its files, read in memory: each
        member by its base name, at most :data:`MAX_FILES` regular files of at most :data:`MAX_FILE_BYTES` (links and
        devices refused), with the folder they are in (the last folder of the members' common one, else the
        archive's name without its suffix: what names a Gepetto ``robot.urdf``); any other upload as it is (no
        folder).

        Raises:
            InvalidInputError: a broken archive, too many or too large members, two members of one name.
        """
        import io
        import tarfile
        import zipfile

        if len(files) != 1:
            return files, None
        (name, data), = files.items()
        lower = name.lower()
        members: dict[str, bytes] = {}
        folders: set[str] = set()

        def take(member: str, content: bytes) -> None:
            parts = member.replace("\\", "/").rsplit("/", 2)
            base = parts[-1]
            if not base:
                return
            folders.add(parts[-2] if len(parts) > 1 else "")
            if base in members or len(members) >= MAX_FILES or len(content) > MAX_FILE_BYTES:
                raise InvalidInputError(name, f"member {member!r}: a repeated name, more than {MAX_FILES} files or "
                                              f"over {MAX_FILE_BYTES} bytes")
            members[base] = content

        try:  # (each member read to one byte past the limit at most: a bomb stops there)
            if lower.endswith(".zip"):
                with zipfile.ZipFile(io.BytesIO(data)) as z:
                    for info in z.infolist():
                        if not info.is_dir():
                            with z.open(info) as fh:
                                take(info.filename, fh.read(MAX_FILE_BYTES + 1))
            elif lower.endswith((".tar", ".tar.gz", ".tgz")):
                with tarfile.open(fileobj=io.BytesIO(data)) as t:
                    for m in t.getmembers():
                        if m.isdir():
                            continue
                        member = t.extractfile(m) if m.isfile() else None
                        if member is None:
                            raise InvalidInputError(name, f"member {m.name!r} is a link or a device")
                        take(m.name, member.read(MAX_FILE_BYTES + 1))
            else:
                return files, None
        except (zipfile.BadZipFile, tarfile.TarError, EOFError, OSError) as e:
            raise InvalidInputError(name, f"not a readable archive: {e}") from None
        if not members:
            raise InvalidInputError(name, "the archive holds no file")
        (folder,) = folders if len(folders) == 1 else ("",)
        stem = name.rsplit("/", 1)[-1]
        for suffix in (".tar.gz", ".tgz", ".tar", ".zip"):
            stem = stem[:-len(suffix)] if stem.lower().endswith(suffix) else stem
        folder = folder if _plain_name(folder) else stem
        return members, folder if _plain_name(folder) else None

    def add(self, files: dict[str, bytes], *, persist: bool = True, folder: str | None = None) -> Entry:
        """Read an upload, keep it, return its entry (the same files: the same entry). ``folder``: the folder the
        files are in, which names a Gepetto ``robot.urdf`` as :func:`pkm.load` does (an archive's own folder
        otherwise).

        Raises:
            InvalidInputError: too many or too large files, a name that is not a plain file name, a file that is
                not UTF-8 text.
            SpecError: what pkm's loaders refuse.
        """
        from pkm.core.formats.load import load_texts

        files, inside = self.unpack(files)
        if not files or len(files) > MAX_FILES:
            raise InvalidInputError("files", f"send 1 to {MAX_FILES} files", len(files))
        total = 0
        texts = {}
        for name, data in files.items():
            if not _plain_name(name):
                raise InvalidInputError("files", "a file name must be a plain name (no folder)", name)
            if len(data) > MAX_FILE_BYTES:
                raise InvalidInputError(name, f"larger than {MAX_FILE_BYTES} bytes", len(data))
            total += len(data)
            try:
                texts[name] = data.decode("utf-8")
            except UnicodeDecodeError as e:
                raise InvalidInputError(name, f"not UTF-8 text (byte {e.start})") from None
        if total > MAX_UPLOAD_BYTES:
            raise InvalidInputError("files", f"larger than {MAX_UPLOAD_BYTES} bytes in all", total)
        folder = naming_folder(files, folder if folder is not None else inside)
        key = upload_id(files, folder)
        with self._lock:
            if key in self._uploads:
                return self._uploads[key]
        mech = load_texts(texts, source=f"upload {key}", folder=folder)
        entry = Entry(key, "uploaded", mech.name, {n: len(d) for n, d in files.items()})
        with self._lock:
            self._uploads[key] = entry
            self._mechanisms[key] = mech
            self._files[key] = dict(files)
        if persist and self.folder is not None:
            place = self.folder / key
            place.mkdir(exist_ok=True)
            hashes = {}
            for name, data in files.items():
                h = hashlib.sha256(data).hexdigest()
                (place / f"{h}.blob").write_bytes(data)
                hashes[name] = h
            (place / "manifest.json").write_text(json.dumps({"files": hashes, "folder": folder}))
        return entry

    def variant(self, model: str, params: dict[str, Any]) -> Entry:
        """A registered mechanism built with other design parameters (:func:`pkm.build`): its entry, id
        ``<name>@<hash of the parameters>`` (the same parameters: the same entry).

        Raises:
            InvalidInputError: ``model`` is not a registered mechanism; the parameters pkm refuses (named).
        """
        import pkm

        if model not in self.registered:
            raise InvalidInputError("model", "variants are of registered mechanisms", model)
        if not isinstance(params, dict) or not all(isinstance(k, str) for k in params):
            raise InvalidInputError("params", "{parameter name: value}", params)
        key = f"{model}@{hashlib.sha256(json.dumps(params, sort_keys=True, default=str).encode()).hexdigest()[:12]}"
        with self._lock:
            if key in self._uploads:
                return self._uploads[key]
        mech = pkm.build(model, **params)
        entry = Entry(key, "variant", mech.name, {})
        with self._lock:
            self._uploads[key] = entry
            self._mechanisms[key] = mech
        return entry

    def entry(self, model: str) -> Entry:
        """The entry of ``model``.

        Raises:
            UnknownNameError: no such model.
        """
        if model in self.registered:
            return Entry(model, "registered", model, {})
        with self._lock:
            if model in self._uploads:
                return self._uploads[model]
        raise UnknownNameError("model", str(model), [e.id for e in self.entries()])

    def files(self, model: str) -> dict[str, bytes]:
        """An upload's files (``{}`` for a registered mechanism)."""
        self.entry(model)
        with self._lock:
            return dict(self._files.get(model, {}))

    def mechanism(self, model: str) -> Mechanism:
        """The mechanism of ``model`` (built once)."""
        import pkm

        self.entry(model)
        with self._lock:
            if model in self._mechanisms:
                return self._mechanisms[model]
        mech = pkm.load(model)
        with self._lock:
            return self._mechanisms.setdefault(model, mech)

    def kernels(self, model: str) -> Any:
        """The compiled kernels of ``model`` for streams (:func:`pkm.serve.stream.kernels_for`), built once; None
        where they do not build."""
        from pkm.serve.stream import kernels_for

        mech = self.mechanism(model)
        with self._lock:
            if model in self._kernels:
                return self._kernels[model]
        K = kernels_for(mech)
        with self._lock:
            return self._kernels.setdefault(model, K)

    def delete(self, model: str) -> None:
        """Forget an upload (and its kept files).

        Raises:
            UnknownNameError: no such upload.
            InvalidInputError: a registered mechanism (they cannot be deleted).
        """
        if model in self.registered:
            raise InvalidInputError("model", "a registered mechanism cannot be deleted", model)
        self.entry(model)
        with self._lock:
            self._uploads.pop(model, None)
            self._mechanisms.pop(model, None)
            self._files.pop(model, None)
            self._kernels.pop(model, None)
        if self.folder is not None:
            place = self.folder / model
            for f in place.glob("*"):
                f.unlink()
            if place.exists():
                place.rmdir()


__all__ = ["MAX_FILES", "MAX_FILE_BYTES", "MAX_UPLOAD_BYTES", "Entry", "Store", "upload_id"]
