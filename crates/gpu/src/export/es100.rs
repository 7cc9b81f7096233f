//! GLSL ES 1.00 (OpenGL ES 2, WebGL 1), derived from naga's GLSL ES 3.00, which naga writes
//! and ES 1.00 mostly shares: ES 1.00 lacks unsigned integers (specula's constants are small,
//! so `int` holds them), `in`/`out` stage variables (`varying` and `gl_FragColor` instead) and
//! every bit operation. A lobe that reads a float's bits (the bit-trick lobes, and `logexp-rr`'s
//! exact power-of-two scaling) has no ES 1.00 form, and is refused with the construct named.

/// What ES 1.00 lacks, as naga writes it in ES 3.00, and what it is called in the refusal.
const UNAVAILABLE: [(&str, &str); 6] = [
    ("floatBitsTo", "bit casts (floatBitsToUint)"),
    ("BitsToFloat", "bit casts (uintBitsToFloat)"),
    ("<<", "shifts"),
    (">>", "shifts"),
    (" & ", "bitwise and"),
    (" | ", "bitwise or"),
];

/// Rewrites naga's ES 3.00 `text` as ES 1.00, or names the construct ES 1.00 lacks.
pub(super) fn from_es300(text: &str) -> Result<String, &'static str> {
    if let Some((_, construct)) = UNAVAILABLE.iter().find(|(token, _)| text.contains(token)) {
        return Err(construct);
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let line = line.trim_end();
        if line == "#version 300 es" {
            out.push_str("#version 100\n");
        } else if line.starts_with("layout(location = 0) out ") {
            // The example's output: ES 1.00 writes `gl_FragColor`.
        } else if let Some(input) = line.strip_prefix("smooth in ") {
            out.push_str("varying ");
            out.push_str(input);
            out.push('\n');
        } else {
            out.push_str(&signed_integers(line).replace("_fs2p_location0 =", "gl_FragColor ="));
            out.push('\n');
        }
    }
    Ok(out)
}

/// `line` with the type `uint` written `int` and unsigned literals (`8u`) written signed.
fn signed_integers(line: &str) -> String {
    let identifier = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = String::with_capacity(line.len());
    let mut rest = line;
    while let Some(c) = rest.chars().next() {
        let word_len = rest.find(|c: char| !identifier(c)).unwrap_or(rest.len());
        if word_len == 0 {
            out.push(c);
            rest = &rest[c.len_utf8()..];
            continue;
        }
        let word = &rest[..word_len];
        let unsigned_literal = word.len() > 1
            && word.ends_with('u')
            && word[..word.len() - 1].bytes().all(|b| b.is_ascii_digit());
        out.push_str(match word {
            "uint" => "int",
            _ if unsigned_literal => &word[..word.len() - 1],
            _ => word,
        });
        rest = &rest[word_len..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unsigned_types_and_literals_become_signed_but_names_stay() {
        assert_eq!(
            signed_integers("const uint g = 12u; uint_x(au, 3u);"),
            "const int g = 12; uint_x(au, 3);"
        );
        assert_eq!(signed_integers("float x = 1.5e3;"), "float x = 1.5e3;");
    }

    #[test]
    fn bit_operations_are_refused_with_the_construct_named() {
        let refused = from_es300("#version 300 es\nuint b = floatBitsToUint(t);\n").unwrap_err();
        assert!(refused.contains("bit casts"), "{refused}");
        let refused = from_es300("#version 300 es\nint k = a << 23;\n").unwrap_err();
        assert!(refused.contains("shifts"), "{refused}");
    }

    #[test]
    fn stage_variables_become_varyings_and_the_output_gl_frag_color() {
        let text = "#version 300 es\nsmooth in vec3 _vs2fs_location0;\nlayout(location = 0) out \
            vec4 _fs2p_location0;\nvoid main() {\n    _fs2p_location0 = vec4(1.0);\n}\n";
        assert_eq!(
            from_es300(text).unwrap(),
            "#version 100\nvarying vec3 _vs2fs_location0;\nvoid main() {\n    gl_FragColor = \
                vec4(1.0);\n}\n"
        );
    }
}
