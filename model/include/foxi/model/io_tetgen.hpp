// TetGen .node / .ele / .face and Medit .mesh.
//
// TetGen: `base` is the path without extension (x.1 for x.1.node, x.1.ele, x.1.face). The .ele's
// first attribute (rounded to an integer) is the region id; the .face's boundary marker the boundary
// tag; .node attributes are ignored; 0- or 1-based numbering as declared by the first index. The
// .face file is optional on reading.
// Medit: Vertices, Tetrahedra (ref -> region), Triangles (ref -> boundary tag); other keywords skipped.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/model/mesh.hpp"

namespace foxi {

Mesh read_tetgen(const std::filesystem::path& base);
// In-memory: the .node and .ele texts are required, .face may be empty; names are for messages.
Mesh parse_tetgen(std::string_view node_text, std::string_view ele_text, std::string_view face_text,
                  const std::string& base_name);
void write_tetgen(const Mesh& mesh, const std::filesystem::path& base);

Mesh read_medit(const std::filesystem::path& path);
Mesh parse_medit(std::string_view bytes, const std::string& name);
void write_medit(const Mesh& mesh, const std::filesystem::path& path);

}  // namespace foxi
