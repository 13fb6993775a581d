"""Package discovery: every contactfx package, plus meshes/ installed as contactfx.meshes.

pyproject.toml holds the metadata; setuptools cannot express "find the packages, and map one
more folder under a new name" there, hence this file.
"""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["contactfx", "contactfx.*"]), "contactfx.meshes"],
    package_dir={"contactfx.meshes": "meshes"},
)
