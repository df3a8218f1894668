#!/bin/sh
# Doxygen's INPUT_FILTER (Doxyfile): foxi's headers comment in plain // lines, so the reference is
# made from them as they are: the comment block that opens a header becomes the file's description,
# a // line before a declaration its documentation, and a // after a member on the same line
# the member's.
exec sed -e '1s|^// |/// \\file\n/// |' \
         -e 's|^\([[:space:]]*\)// |\1/// |' \
         -e 's|^\([[:space:]]*\)//$|\1///|' \
         -e 's|\([;,{]\)\([[:space:]]*\)// |\1\2///< |' "$1"
