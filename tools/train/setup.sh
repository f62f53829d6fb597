#!/usr/bin/env bash
# Create the training venv at tools/train/.venv (gitignored). Never run by CI.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
python3 -m venv "$here/.venv"
"$here/.venv/bin/pip" install --upgrade pip
"$here/.venv/bin/pip" install -r "$here/requirements.txt"
# triton (~1 GB) is only needed by torch.compile, which training does not use.
"$here/.venv/bin/pip" uninstall -y triton || true
"$here/.venv/bin/python" -c "import torch, torchvision, onnx, onnxruntime; print('torch', torch.__version__, 'onnxruntime', onnxruntime.__version__)"
