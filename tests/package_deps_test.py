#!/usr/bin/env python3
"""package.xml against the code: every ROS package the sources use is declared, and every ROS
package declared is used.

A package only used without being declared builds here because another one pulls it in
(camera_node's ros/package.h came with camera_info_manager's roslib), and breaks the day that one
stops; one declared but unused is linked into every node for nothing. A ROS package is one that
Debian installs with /usr/share/<name>/package.xml.

Usage: package_deps_test.py [SOURCE_DIR]   (default: this file's project)
Input: C++ #include <pkg/...> under src, nodes, tools, tests and bench; Python import/from in
tests, scripts, nodes and tools; pkg="..." in launch files and rostests; message types in msg/
and action/; generate_messages(DEPENDENCIES ...) in CMakeLists.txt.
Output: exit 0, or 1 naming each package used but undeclared (with a file using it) and each
declared but unused.
"""
import os
import re
import sys
import xml.etree.ElementTree as ET

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..'))
SHARE = os.environ.get('ROS_PACKAGE_SHARE', '/usr/share')
# Packages a catkin package needs whatever its code says (the build tool and message generation).
IMPLIED = {'catkin', 'message_generation', 'message_runtime', 'rostest'}


def is_ros_package(name):
    return os.path.isfile(os.path.join(SHARE, name, 'package.xml'))


def declared(package_xml):
    tags = ('depend', 'build_depend', 'exec_depend', 'test_depend', 'build_export_depend', 'buildtool_depend')
    root = ET.parse(package_xml).getroot()
    return {e.text.strip() for t in tags for e in root.iter(t) if e.text}


def files_under(dirs, suffixes):
    for d in dirs:
        for base, subdirs, names in os.walk(os.path.join(ROOT, d)):
            subdirs[:] = [s for s in subdirs if not s.startswith('.')]
            for n in names:
                if n.endswith(suffixes):
                    yield os.path.join(base, n)


def used():
    """Returns {package: first file (relative) that uses it}."""
    uses = {}

    def add(pkg, path):
        if is_ros_package(pkg):
            uses.setdefault(pkg, os.path.relpath(path, ROOT))

    include = re.compile(r'^\s*#\s*include\s*<([A-Za-z0-9_]+)/([^>]+)>', re.M)
    for path in files_under(('src', 'nodes', 'tools', 'tests', 'bench'), ('.h', '.cc', '.cpp', '.hpp')):
        for pkg, rest in include.findall(open(path, encoding='utf-8').read()):
            # ros/ holds headers of several packages: package.h is roslib's, the rest roscpp's.
            if pkg == 'ros':
                pkg = 'roslib' if rest == 'package.h' else 'roscpp'
            add(pkg, path)
    imports = re.compile(r'^\s*(?:import|from)\s+([A-Za-z0-9_]+)', re.M)
    for path in files_under(('tests', 'scripts', 'nodes', 'tools'), ('.py',)):
        for pkg in imports.findall(open(path, encoding='utf-8').read()):
            add(pkg, path)
    launch_pkg = re.compile(r'\bpkg="([A-Za-z0-9_]+)"')
    for path in files_under(('launch', 'tests'), ('.launch', '.test')):
        for pkg in launch_pkg.findall(open(path, encoding='utf-8').read()):
            add(pkg, path)
    msg_type = re.compile(r'^\s*([A-Za-z0-9_]+)/[A-Za-z0-9_]+(?:\[\d*\])?\s', re.M)
    for path in files_under(('msg', 'action'), ('.msg', '.action')):
        for pkg in msg_type.findall(open(path, encoding='utf-8').read()):
            add(pkg, path)
    cmake = open(os.path.join(ROOT, 'CMakeLists.txt'), encoding='utf-8').read()
    for deps in re.findall(r'generate_messages\s*\(\s*DEPENDENCIES([^)]*)\)', cmake):
        for pkg in deps.split():
            add(pkg, os.path.join(ROOT, 'CMakeLists.txt'))
    if os.path.isdir(os.path.join(ROOT, 'action')) and os.listdir(os.path.join(ROOT, 'action')):
        add('actionlib_msgs', os.path.join(ROOT, 'action'))  # generated action messages use its types
    return uses


def main():
    decl = declared(os.path.join(ROOT, 'package.xml'))
    uses = used()
    problems = []
    for pkg, where in sorted(uses.items()):
        if pkg != 'clothwind' and pkg not in decl:
            problems.append(f'{pkg}: used ({where}) but not declared in package.xml')
    for pkg in sorted(decl):
        if is_ros_package(pkg) and pkg not in uses and pkg not in IMPLIED:
            problems.append(f'{pkg}: declared in package.xml but nothing uses it')
    if not uses:
        problems.append(f'no ROS package found in use under {ROOT} ({SHARE}/<name>/package.xml missing?)')
    for p in problems:
        print('package_deps_test: FAIL: ' + p, file=sys.stderr)
    if problems:
        return 1
    print(f'package_deps_test: OK ({len(uses)} ROS packages used, all declared; none declared unused)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
