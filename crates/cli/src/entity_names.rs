//! Names of IGES entity types (IGES 5.3), so that `info` prints `128 B-spline surface`
//! rather than a bare number. STEP files name their entities themselves.

/// The IGES 5.3 name of entity type `n`, when it is a type the standard defines.
pub fn iges(n: u32) -> Option<&'static str> {
    Some(match n {
        0 => "null",
        100 => "circular arc",
        102 => "composite curve",
        104 => "conic arc",
        106 => "copious data",
        108 => "plane",
        110 => "line",
        112 => "parametric spline curve",
        114 => "parametric spline surface",
        116 => "point",
        118 => "ruled surface",
        120 => "surface of revolution",
        122 => "tabulated cylinder",
        123 => "direction",
        124 => "transformation matrix",
        125 => "flash",
        126 => "B-spline curve",
        128 => "B-spline surface",
        130 => "offset curve",
        132 => "connect point",
        134 => "node",
        136 => "finite element",
        138 => "nodal displacement and rotation",
        140 => "offset surface",
        141 => "boundary",
        142 => "curve on a parametric surface",
        143 => "bounded surface",
        144 => "trimmed surface",
        146 => "nodal results",
        148 => "element results",
        150 => "block",
        152 => "right angular wedge",
        154 => "right circular cylinder",
        156 => "right circular cone frustum",
        158 => "sphere",
        160 => "torus",
        162 => "solid of revolution",
        164 => "solid of linear extrusion",
        168 => "ellipsoid",
        180 => "boolean tree",
        182 => "selected component",
        184 => "solid assembly",
        186 => "manifold solid B-rep object",
        190 => "plane surface",
        192 => "right circular cylindrical surface",
        194 => "right circular conical surface",
        196 => "spherical surface",
        198 => "toroidal surface",
        202 => "angular dimension",
        204 => "curve dimension",
        206 => "diameter dimension",
        208 => "flag note",
        210 => "general label",
        212 => "general note",
        213 => "new general note",
        214 => "leader (arrow)",
        216 => "linear dimension",
        218 => "ordinate dimension",
        220 => "point dimension",
        222 => "radius dimension",
        228 => "general symbol",
        230 => "sectioned area",
        302 => "associativity definition",
        304 => "line font definition",
        306 => "macro definition",
        308 => "subfigure definition",
        310 => "text font definition",
        312 => "text display template",
        314 => "color definition",
        316 => "units data",
        320 => "network subfigure definition",
        322 => "attribute table definition",
        402 => "associativity instance",
        404 => "drawing",
        406 => "property",
        408 => "singular subfigure instance",
        410 => "view",
        412 => "rectangular array subfigure instance",
        414 => "circular array subfigure instance",
        416 => "external reference",
        418 => "nodal load/constraint",
        420 => "network subfigure instance",
        422 => "attribute table instance",
        430 => "solid instance",
        502 => "vertex list",
        504 => "edge list",
        508 => "loop",
        510 => "face",
        514 => "shell",
        _ => return None,
    })
}

/// The name `info` prints for an entity-count key: `128 B-spline surface` for IGES
/// (`128 (type not in IGES 5.3)` for others), the key itself for STEP.
pub fn display(format: cadmorph::Format, key: &str) -> String {
    match format {
        cadmorph::Format::Iges => match key.parse().ok().and_then(iges) {
            Some(name) => format!("{key} {name}"),
            None => format!("{key} (type not in IGES 5.3)"),
        },
        cadmorph::Format::Step => key.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn names() {
        assert_eq!(super::display(cadmorph::Format::Iges, "128"), "128 B-spline surface");
        assert_eq!(super::display(cadmorph::Format::Iges, "999"), "999 (type not in IGES 5.3)");
        assert_eq!(super::display(cadmorph::Format::Step, "B_SPLINE_SURFACE"), "B_SPLINE_SURFACE");
    }
}
