// Saving a model file with edited parameter values: the source file's text with only the edited
// values replaced (comments, key order, materials, conditions and formatting kept), and, when it is
// saved into another folder, its referenced files (material library, STL surfaces) renamed relative
// to the new folder so that they still name the same files.
#pragma once

#include <filesystem>
#include <span>

#include "foxi/api.hpp"
#include "foxi/model/model_file.hpp"

namespace foxi {

// Writes the model file `source` with `values` applied to `target` (which may be `source` itself).
// Each value replaces the expression of its parameter in the file ("8 mm", "2 * die_w"); a parameter
// the file does not have is an error. The file appears whole or not at all (a durable temporary
// renamed over the target) and only after the temporary loads back (load_model) to a model equal to
// `source` loaded with `values`: the same parameters (names, expressions, values), materials and
// parts (shapes, outlines, surfaces), and the same conditions, loads and surfaces counted; otherwise
// nothing is written. Throws IoError naming the file, the line (when known) and the reason: the
// source does not load, a value is not written as one line, a referenced file cannot be named
// relative to the target's folder, or the saved model would load differently.
struct SaveModelOptions {
  // Copy the referenced files (material library, STL surfaces) into the target's folder, each under
  // its own file name (two different files of one name: the second as "NAME-2.EXT"), and name the
  // copies: the folder then holds a model that needs nothing outside it (a workbench project folder,
  // moved or sent to another machine). The copies are written before the model file (its load-back
  // check reads them); a refused model leaves them there. Otherwise the references are renamed to
  // the same files, relative to the target's folder.
  bool copy_references = false;
};
FOXI_API void save_model(const std::filesystem::path& source, const std::filesystem::path& target,
                         std::span<const ParameterOverride> values, const SaveModelOptions& options = {});

}  // namespace foxi
