"""The type stubs (python/pegasus/_pegasus.pyi) against the compiled module: every function and method both
define takes the same parameter names (keywords a user writes from the stub must work at runtime). That every
compiled name has a stub is test_training.py's."""
import ast
import pathlib
import re

import pegasus._pegasus as compiled

STUB = pathlib.Path(compiled.__file__).with_name("_pegasus.pyi")


def stub_signatures():
    tree = ast.parse(STUB.read_text())
    signatures = {}

    def parameters(function):
        a = function.args
        names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg not in ("self", "cls")]
        return names + ([f"*{a.vararg.arg}"] if a.vararg else []) + ([f"**{a.kwarg.arg}"] if a.kwarg else [])

    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            signatures[node.name] = parameters(node)
        elif isinstance(node, ast.ClassDef):
            for member in node.body:
                if isinstance(member, ast.FunctionDef) and not any(
                        isinstance(d, ast.Name) and d.id == "property" for d in member.decorator_list):
                    signatures[f"{node.name}.{member.name}"] = parameters(member)
    return signatures


def runtime_overloads(function, name):
    """The parameter names of each overload pybind11 writes at the top of the docstring."""
    overloads = []
    for line in (function.__doc__ or "").splitlines():
        match = re.match(rf"^(?:\d+\. )?{re.escape(name)}\((.*)\) ->", line)
        if not match:
            continue
        depth, current, parts = 0, "", []
        for ch in match.group(1):
            depth += ch in "([{"
            depth -= ch in ")]}"
            if ch == "," and depth == 0:
                parts.append(current)
                current = ""
            else:
                current += ch
        parts.append(current)
        names = [p.split(":")[0].split("=")[0].strip() for p in parts]
        overloads.append([n for n in names if n and n not in ("self", "*", "/")])
    return overloads


def test_stubbed_functions_and_methods_take_the_runtime_parameter_names():
    signatures = stub_signatures()
    checked, wrong = 0, []
    for key, stub_parameters in signatures.items():
        owner, _, member = key.rpartition(".")
        holder = getattr(compiled, owner, None) if owner else compiled  # None: a stub-only typing base
        target = getattr(holder, member, None)
        if target is None or not callable(target):
            continue
        overloads = runtime_overloads(target, member)
        if not overloads:
            continue  # pure Python, or a stub-only typing helper
        checked += 1
        if stub_parameters not in overloads:
            wrong.append(f"{key}: stub {stub_parameters}, runtime {overloads}")
    assert wrong == []
    assert checked >= 100  # the comparison reached the module, not an empty docstring set


def test_the_checked_in_stub_is_the_one_generated_from_the_compiled_module(source_dir):
    # The stub is written by scripts/generate_stubs.py from the compiled module (issue 49): a binding changed
    # without regenerating it fails here, with the lines that differ.
    import difflib
    import importlib.util

    spec = importlib.util.spec_from_file_location("generate_stubs", source_dir / "scripts" / "generate_stubs.py")
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    generated = generator.generate(compiled)
    checked_in = (source_dir / "python" / "pegasus" / "_pegasus.pyi").read_text()
    difference = "".join(difflib.unified_diff(checked_in.splitlines(True), generated.splitlines(True),
                                              "checked in", "generated", n=1))
    assert difference == "", ("python/pegasus/_pegasus.pyi is not what the compiled module gives: run "
                              "PYTHONPATH=build/python /usr/bin/python3 scripts/generate_stubs.py\n" + difference[:4000])
    # What a type checker needs from it: every parameter and return typed, none as a bare object.
    tree = ast.parse(checked_in)
    untyped = [f"{node.name}.{a.arg}" for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)
               for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs
               if a.arg not in ("self", "cls") and a.annotation is None]
    assert untyped == []
