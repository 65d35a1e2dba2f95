"""Packaging: the top-level ``xacro/`` and ``urdf/`` travel in the wheel as ``legkin/xacro`` and ``legkin/urdf``.

Everything else is in pyproject.toml. The source tree keeps the layout users of this field expect (``xacro/``,
``urdf/`` at the top); ``legkin._generate.root_dir`` finds them there or in the installed package.
"""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages("src"), "legkin.xacro", "legkin.urdf", "legkin.urdf.meshes"],
    package_dir={"": "src", "legkin.xacro": "xacro", "legkin.urdf": "urdf", "legkin.urdf.meshes": "urdf/meshes"},
    package_data={
        "legkin": ["py.typed"],
        "legkin.xacro": ["*.xacro"],
        "legkin.urdf": ["*.urdf", "*.srdf"],
        "legkin.urdf.meshes": ["*.stl"],
    },
)
