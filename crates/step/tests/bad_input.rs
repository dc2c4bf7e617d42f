//! Bad input gets an error naming line, column and instance; nothing panics.

use cadmorph_step::{Document, EntityId, Error};
use proptest::prelude::*;

fn wrap(data: &str) -> String {
    format!("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nENDSEC;\nDATA;\n{data}ENDSEC;\nEND-ISO-10303-21;\n")
}

/// A one-face shell whose surface is `surface` (instance #20), for view errors.
fn face_with(surface: &str) -> String {
    wrap(&format!(
        "#1 = SHAPE_REPRESENTATION('',(#2),#3);\n#2 = SHELL_BASED_SURFACE_MODEL('',(#4));\n\
         #3 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#6)) REPRESENTATION_CONTEXT('','') );\n\
         #4 = OPEN_SHELL('',(#5));\n#5 = ADVANCED_FACE('',(),#20,.T.);\n\
         #6 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n{surface}\n"
    ))
}

fn pos(e: &Error) -> (usize, usize, Option<EntityId>) {
    let p = e.position().expect("the error names a position");
    (p.line, p.column, p.id)
}

#[test]
fn unterminated_string() {
    let e = Document::parse(wrap("#1 = CARTESIAN_POINT('abc,(0.,0.,0.));\n").as_bytes()).unwrap_err();
    assert!(matches!(e, Error::UnterminatedString { .. }), "{e}");
    assert_eq!(pos(&e), (6, 22, Some(EntityId(1))));
}

#[test]
fn dangling_reference() {
    let e = Document::parse(wrap("#1 = VERTEX_POINT('',#2);\n#3 = VERTEX_POINT('',#1);\n").as_bytes()).unwrap_err();
    assert!(matches!(e, Error::DanglingReference { target: EntityId(2), .. }), "{e}");
    assert_eq!(pos(&e), (6, 22, Some(EntityId(1))));
    // Held by a later instance, after a complex one.
    let data = "#1 = VERTEX_POINT('',#3);\n#4 = ( A(#1) B() );\n#3 = VERTEX_POINT('',\n#9);\n";
    let e = Document::parse(wrap(data).as_bytes()).unwrap_err();
    assert!(matches!(e, Error::DanglingReference { target: EntityId(9), .. }), "{e}");
    assert_eq!(pos(&e), (9, 1, Some(EntityId(3))));
}

#[test]
fn duplicate_id() {
    let e = Document::parse(wrap("#1 = DIRECTION('',(1.,0.,0.));\n#1 = DIRECTION('',(1.,0.,0.));\n").as_bytes())
        .unwrap_err();
    assert!(matches!(e, Error::DuplicateId { first_line: 6, .. }), "{e}");
    assert_eq!(pos(&e), (7, 1, Some(EntityId(1))));
}

#[test]
fn reference_cycles() {
    // A trimmed surface that trims itself.
    let doc = Document::parse(face_with("#20 = RECTANGULAR_TRIMMED_SURFACE('',#20,0.,1.,0.,1.,.T.,.T.);").as_bytes())
        .unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::ReferenceCycle { target: EntityId(20), .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(20)));
    assert!(pos(&e).0 > 0);
    // A unit defined through itself.
    let doc = Document::parse(
        wrap(
            "#1 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#2)) REPRESENTATION_CONTEXT('','') );\n\
             #2 = ( CONVERSION_BASED_UNIT('X',#3) LENGTH_UNIT() NAMED_UNIT(*) );\n\
             #3 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(2.),#2);\n",
        )
        .as_bytes(),
    )
    .unwrap();
    let e = doc.units().unwrap_err();
    assert!(matches!(e, Error::ReferenceCycle { target: EntityId(2), .. }), "{e}");
    // Representations joined without transformations, round in a circle, are one shape
    // (OCCT follows such relationships both ways): read once, no cycle.
    let doc = Document::parse(
        wrap(
            "#1 = SHAPE_REPRESENTATION('',(),$);\n#2 = SHAPE_REPRESENTATION('',(),$);\n\
             #3 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#1,#2);\n#4 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#2,#1);\n\
             #5 = SHAPE_REPRESENTATION('',(),$);\n#6 = SHAPE_REPRESENTATION_RELATIONSHIP('','',#1,#5);\n",
        )
        .as_bytes(),
    )
    .unwrap();
    assert!(doc.faces().unwrap().is_empty());
    // Two representations placed in each other (relationships with transformations).
    let placed = |id: u64, child: u64, parent: u64| {
        format!(
            "#{id} = ( REPRESENTATION_RELATIONSHIP('','',#{child},#{parent}) \
             REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#9) SHAPE_REPRESENTATION_RELATIONSHIP() );\n"
        )
    };
    let doc = Document::parse(
        wrap(&format!(
            "#1 = SHAPE_REPRESENTATION('',(),$);\n#2 = SHAPE_REPRESENTATION('',(),$);\n\
             #5 = SHAPE_REPRESENTATION('',(),$);\n#7 = CARTESIAN_POINT('',(0.,0.,0.));\n\
             #8 = AXIS2_PLACEMENT_3D('',#7,$,$);\n#9 = ITEM_DEFINED_TRANSFORMATION('','',#8,#8);\n{}{}{}",
            placed(3, 1, 2),
            placed(4, 2, 1),
            placed(6, 1, 5)
        ))
        .as_bytes(),
    )
    .unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::ReferenceCycle { .. }), "{e}");
}

/// Two shape representations `#1` (a product's, `#30`) and `#2`, with the `MAPPED_ITEM`s
/// `extra` (instances #10 on).
fn mapped(extra: &str, items1: &str, items2: &str) -> String {
    wrap(&format!(
        "#1 = SHAPE_REPRESENTATION('',({items1}),$);\n#2 = SHAPE_REPRESENTATION('',({items2}),$);\n\
         #5 = CARTESIAN_POINT('',(0.,0.,0.));\n#6 = AXIS2_PLACEMENT_3D('',#5,$,$);\n\
         #30 = SHAPE_DEFINITION_REPRESENTATION(#5,#1);\n{extra}"
    ))
}

#[test]
fn mapped_item_cycles_and_bad_maps_name_the_instance() {
    // #1 maps #2 (item #10), #2 maps #1 back (item #12): the cycle closes at #12.
    let doc = Document::parse(
        mapped(
            "#10 = MAPPED_ITEM('a',#11,#6);\n#11 = REPRESENTATION_MAP(#6,#2);\n\
             #12 = MAPPED_ITEM('b',#13,#6);\n#13 = REPRESENTATION_MAP(#6,#1);\n",
            "#10",
            "#12",
        )
        .as_bytes(),
    )
    .unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::ReferenceCycle { target: EntityId(1), .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(12)), "{e}");
    // A representation that maps itself.
    let doc = Document::parse(
        mapped("#10 = MAPPED_ITEM('a',#11,#6);\n#11 = REPRESENTATION_MAP(#6,#1);\n", "#10", "").as_bytes(),
    )
    .unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::ReferenceCycle { target: EntityId(1), .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(10)), "{e}");
    // A target that is not a placement, a source that is not a map.
    let doc = Document::parse(
        mapped("#10 = MAPPED_ITEM('a',#11,#5);\n#11 = REPRESENTATION_MAP(#6,#2);\n", "#10", "").as_bytes(),
    )
    .unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::UnexpectedEntity { expected: "AXIS2_PLACEMENT_3D", .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(5)), "{e}");
    let doc = Document::parse(mapped("#10 = MAPPED_ITEM('a',#6,#6);\n", "#10", "").as_bytes()).unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::UnexpectedEntity { expected: "REPRESENTATION_MAP", .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(6)), "{e}");
    // A representation mapped twice into the next, 40 deep: 2^40 placements refused.
    let mut text = String::new();
    for k in 0..40 {
        let (rep, map, a, b) = (100 + 4 * k, 101 + 4 * k, 102 + 4 * k, 103 + 4 * k);
        let inner = if k == 39 { "".to_string() } else { format!("#{a},#{b}") };
        text += &format!("#{rep} = SHAPE_REPRESENTATION('',({inner}),$);\n#{map} = REPRESENTATION_MAP(#6,#{rep});\n");
        if k > 0 {
            let (pa, pb, pmap) = (a - 4, b - 4, map);
            text += &format!("#{pa} = MAPPED_ITEM('',#{pmap},#6);\n#{pb} = MAPPED_ITEM('',#{pmap},#6);\n");
        }
    }
    text += "#10 = MAPPED_ITEM('',#101,#6);\n";
    let doc = Document::parse(mapped(&text, "#10", "").as_bytes()).unwrap();
    let e = doc.faces().unwrap_err();
    assert!(matches!(e, Error::Limit { .. }), "{e}");
    eprintln!("{e}");
}

#[test]
fn wrong_arity() {
    let doc = Document::parse(wrap("\n#7 = CARTESIAN_POINT('',(0.,0.,0.),5.);\n").as_bytes()).unwrap();
    let e = doc.point(EntityId(7)).unwrap_err();
    assert!(matches!(e, Error::Arity { expected: 2, found: 3, .. }), "{e}");
    assert_eq!(pos(&e), (7, 6, Some(EntityId(7))));
    let doc =
        Document::parse(face_with("#20 = CYLINDRICAL_SURFACE('',#21);\n#21 = DIRECTION('',(0.,0.,1.));").as_bytes())
            .unwrap();
    let f = &doc.faces().unwrap()[0];
    let e = doc.face_nurbs(f).unwrap_err();
    assert!(matches!(e, Error::Arity { .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(20)));
}

#[test]
fn wrong_parameter_type() {
    let doc = Document::parse(wrap("#7 = CARTESIAN_POINT('',(0.,'x',0.));\n").as_bytes()).unwrap();
    let e = doc.point(EntityId(7)).unwrap_err();
    assert!(matches!(e, Error::Parameter { index: 1, .. }), "{e}");
    assert_eq!(pos(&e), (6, 29, Some(EntityId(7))));
}

#[test]
fn truncated_files() {
    let bytes = std::fs::read(cadmorph_testkit::sample("mixed_solid.stp")).unwrap();
    for cut in (0..bytes.len()).step_by(97) {
        match Document::parse(&bytes[..cut]) {
            Ok(_) => panic!("a file cut at {cut} parsed"),
            Err(e) => assert!(e.position().is_some_and(|p| p.line > 0), "{e}"),
        }
    }
    let e = Document::parse(&bytes[..bytes.len() / 2]).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. } | Error::Syntax { .. } | Error::UnterminatedString { .. }), "{e}");
    let e = Document::parse(b"ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = DIRECTION('',(1.,0.,").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert_eq!(pos(&e).2, Some(EntityId(1)));
}

#[test]
fn limits() {
    let deep = format!("#1 = A({}{});\n", "(".repeat(200), ")".repeat(200));
    assert!(matches!(Document::parse(wrap(&deep).as_bytes()).unwrap_err(), Error::Limit { .. }));
    let big = wrap("#99999999999999999999999 = A();\n");
    assert!(matches!(Document::parse(big.as_bytes()).unwrap_err(), Error::Limit { .. }));
    // Knot multiplicities far beyond the input.
    let doc = Document::parse(
        face_with(
            "#20 = B_SPLINE_SURFACE_WITH_KNOTS('',1,1,((#21,#21),(#21,#21)),.UNSPECIFIED.,.F.,.F.,.F.,(2,2),(2,1000000000000),(0.,1.),(0.,1.),.UNSPECIFIED.);\n#21 = CARTESIAN_POINT('',(0.,0.,0.));",
        )
        .as_bytes(),
    )
    .unwrap();
    let f = &doc.faces().unwrap()[0];
    assert!(doc.face_nurbs(f).is_err());
}

/// Every message, for review of the wording.
#[test]
fn messages() {
    let cases = [
        wrap("#1 = CARTESIAN_POINT('abc,(0.,0.,0.));\n"),
        wrap("#1 = VERTEX_POINT('',#2);\n"),
        wrap("#1 = DIRECTION('',(1.,0.,0.));\n#1 = DIRECTION('',(1.,0.,0.));\n"),
        wrap("#1 = DIRECTION('',(1.,0.,0.)) #2;\n"),
        wrap("#1 = DIRECTION('',(1.,,0.));\n"),
        "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = DIRECTION('',(1.,0.,0.));\n".into(),
        "ISO-10303-21;\nHEADER;\n/* never closed".into(),
        "not a step file".into(),
    ];
    for c in cases {
        let e = Document::parse(c.as_bytes()).unwrap_err();
        eprintln!("{e}");
        assert!(e.to_string().starts_with("line "), "{e}");
    }
}

fn sample_bytes() -> Vec<Vec<u8>> {
    ["nurbs_cylinder.stp", "bspline_curve.stp", "mixed_solid.stp"]
        .iter()
        .map(|n| std::fs::read(cadmorph_testkit::sample(n)).unwrap())
        .collect()
}

/// Parses, views and writes whatever the mutation left; must never panic.
fn exercise(bytes: &[u8]) {
    if let Ok(doc) = Document::parse(bytes) {
        assert_eq!(doc.write(), bytes);
        let _ = doc.units();
        let _ = doc.entity_counts();
        if let Ok(faces) = doc.faces() {
            for f in faces.iter().take(20) {
                let _ = doc.face_nurbs(f);
            }
            if let Ok(edges) = doc.edges(&faces) {
                for e in edges.iter().take(40) {
                    let _ = doc.edge_curve(e);
                }
            }
        }
    }
}

#[derive(Debug, Clone)]
enum Mutation {
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let byte = prop_oneof![
        Just(b'('),
        Just(b')'),
        Just(b','),
        Just(b';'),
        Just(b'\''),
        Just(b'#'),
        Just(b'$'),
        Just(b'*'),
        Just(b'.'),
        Just(b'-'),
        Just(b'9'),
        Just(b'E'),
        Just(b'/'),
        any::<u8>()
    ];
    prop_oneof![
        (any::<usize>(), byte.clone()).prop_map(|(i, b)| Mutation::Set(i, b)),
        (any::<usize>(), byte).prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<usize>(), 1usize..40).prop_map(|(i, n)| Mutation::Delete(i, n)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    #[test]
    fn mutated_samples_never_panic(which in 0usize..3, muts in proptest::collection::vec(mutation(), 1..6)) {
        let mut b = sample_bytes().swap_remove(which);
        for m in muts {
            let n = b.len().max(1);
            match m {
                Mutation::Set(i, x) => { let i = i % n; if i < b.len() { b[i] = x; } }
                Mutation::Insert(i, x) => b.insert(i % (b.len() + 1), x),
                Mutation::Delete(i, k) => { let i = i % n; let e = (i + k).min(b.len()); if i < e { b.drain(i..e); } }
                Mutation::Truncate(i) => b.truncate(i % n),
            }
        }
        exercise(&b);
    }
}

/// A bicubic B-spline surface `#20` of `n × n` poles `#1000…` on z = x·y, with the text of
/// pole `odd` replaced by `odd_text` (its parameters, after `CARTESIAN_POINT`).
fn big_net(n: usize, odd: usize, odd_text: &str) -> String {
    let mut data = String::new();
    let refs: Vec<String> = (0..n)
        .map(|i| format!("({})", (0..n).map(|j| format!("#{}", 1000 + i * n + j)).collect::<Vec<_>>().join(",")))
        .collect();
    let knots = |n: usize| format!("({})", (0..n - 2).map(|k| k.to_string() + ".").collect::<Vec<_>>().join(","));
    let mults = |n: usize| format!("(4,{}4)", "1,".repeat(n - 4));
    data.push_str(&format!(
        "#20 = B_SPLINE_SURFACE_WITH_KNOTS('',3,3,({}),.UNSPECIFIED.,.F.,.F.,.F.,{},{},{},{},.UNSPECIFIED.);\n",
        refs.join(","),
        mults(n),
        mults(n),
        knots(n),
        knots(n)
    ));
    for i in 0..n {
        for j in 0..n {
            let k = i * n + j;
            let (x, y) = (i as f64 * 0.5, j as f64 * 0.25);
            if k == odd {
                data.push_str(&format!("#{} = CARTESIAN_POINT{odd_text};\n", 1000 + k));
            } else {
                data.push_str(&format!("#{} = CARTESIAN_POINT('',({x:?},{y:?},{:?}));\n", 1000 + k, x * y));
            }
        }
    }
    wrap(&data)
}

/// A net large enough to be read on several threads reads every pole, a pole in a form
/// the fast reader declines (a comment, an integer) included, and a bad pole is reported
/// with its own instance, as on one thread.
#[test]
fn large_pole_nets_read_every_pole_and_name_the_bad_one() {
    let n = 70; // 4 900 poles: past the parallel threshold
    let odd = 2 * n + 5; // pole (2, 5): x = 1, y = 1.25
    let doc = Document::parse(big_net(n, odd, "('' , ( 1 , 1.25 /* c */ , 1.25E0 ))").as_bytes()).unwrap();
    let s = doc.bspline_surface(EntityId(20)).unwrap();
    let pts = s.control_points();
    assert_eq!(pts.len(), n * n);
    for (k, p) in pts.iter().enumerate() {
        let (x, y) = ((k / n) as f64 * 0.5, (k % n) as f64 * 0.25);
        assert_eq!((p.x, p.y, p.z), (x, y, x * y), "pole {k}");
    }
    let doc = Document::parse(big_net(n, odd, "('',(1.,'y',3.))").as_bytes()).unwrap();
    let e = doc.bspline_surface(EntityId(20)).unwrap_err();
    assert_eq!(pos(&e).2, Some(EntityId(1000 + odd as u64)), "{e}");
}
