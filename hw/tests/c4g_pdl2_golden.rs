//! Golden checks of the C4G line protocol against the PDL2 program that serves it on the
//! controller (`hw/pdl2/nbv_server.pdl`), not against the Rust code's own output: the
//! command words, argument counts and line sizes the program reads; every reply line the
//! program builds (its `send(…)` expressions, evaluated with sample values) through the
//! client's decoder; and hand-written lines in the program's formats through the encoder
//! and decoder. the public C4G PDL2 servers: line-based ASCII over a TCP server
//! socket on the controller's `'NETT:'` device, a function code then the values as text,
//! `OK` per command and again when the motion completes.
#![cfg(feature = "comau")]

use nbv_hw::comau::protocol::{Command, ErrorCode, MAX_LINE, PROTOCOL_VERSION, Reply};
use std::collections::BTreeMap;

const PDL2: &str = include_str!("../pdl2/nbv_server.pdl");

/// The program's code without its `--` comments (no string literal in it holds `--`).
fn code() -> String {
    PDL2.lines()
        .map(|l| l.split("--").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The quoted literal that follows `prefix` at each of its occurrences.
fn literals_after(code: &str, prefix: &str) -> Vec<String> {
    code.match_indices(prefix)
        .map(|(i, _)| {
            let rest = &code[i + prefix.len()..];
            rest[..rest.find('\'').unwrap()].to_owned()
        })
        .collect()
}

/// The body of the `CASE ('<word>'):` branch, up to the next `CASE` or `ELSE:`.
fn case_body(code: &str, word: &str) -> String {
    let start = code.find(&format!("CASE ('{word}'):")).unwrap();
    let rest = &code[start + 1..];
    let end = ["CASE (", "ELSE:"]
        .iter()
        .filter_map(|m| rest.find(m))
        .min()
        .unwrap();
    rest[..end].to_owned()
}

/// The declared length of a PDL2 `STRING[n]` variable.
fn string_length(code: &str, variable: &str) -> usize {
    let line = code
        .lines()
        .find(|l| l.contains(variable) && l.contains("STRING["))
        .unwrap_or_else(|| panic!("no STRING declaration of {variable}"));
    let n = &line[line.find("STRING[").unwrap() + 7..];
    n[..n.find(']').unwrap()].parse().unwrap()
}

#[test]
fn the_program_speaks_this_protocol_version_and_line_length() {
    let code = code();
    assert_eq!(
        literals_after(&code, "ks_version = '"),
        [PROTOCOL_VERSION.to_string()]
    );
    // `READ vi_lun (vs_line)` into a STRING[256]: the longest line either side sends.
    assert_eq!(string_length(&code, "vs_line"), MAX_LINE);
    // One public PDL2 server listens on port 12345; so does this one.
    assert!(code.contains("ki_port = 12345"));
}

#[test]
fn every_command_the_client_encodes_is_one_the_program_reads() {
    let code = code();
    let words: Vec<String> = literals_after(&code, "CASE ('");
    assert_eq!(
        words,
        ["HELLO", "OVR", "JNT", "POS", "MOVE", "STOP", "BYE"],
        "the program's commands changed: update the client and this test"
    );
    // How many numbers each branch accepts (`vi_n`, from parse_line), none where unchecked.
    let arity: BTreeMap<&str, usize> = words
        .iter()
        .map(|w| {
            let body = case_body(&code, w);
            let n = body
                .find("vi_n = ")
                .map_or(0, |i| body[i + 7..i + 8].parse().unwrap());
            (w.as_str(), n)
        })
        .collect();
    assert_eq!(arity["OVR"], 1);
    assert_eq!(arity["MOVE"], 6);
    // During a motion the program only looks for a line starting with STOP.
    assert!(code.contains("STR_LOC(vs_line, 'STOP') = 1"));

    // parse_line: STR_TOKENS on single spaces; the rest of the line after the command word
    // goes through `lw : STRING[64]`, so a MOVE's six values must fit in 64 characters.
    let rest_max = string_length(&code, "lw");
    assert_eq!(rest_max, 64);
    // Hand-written lines of the client's encoder, down to the decimals (the program reads
    // them with STR_TO_REAL). The MOVE is at the strokes' ends (the SMART SiX 6-1.4
    // data sheet: J1 ±170°, J2 −85…+155°, J3 −170…0°, J4 ±210°, J5 ±130°, J6 ±2700°).
    let golden = [
        (Command::Hello, "HELLO"),
        (Command::Override(25), "OVR 25"),
        (Command::Joints, "JNT"),
        (Command::Pose, "POS"),
        (
            Command::Move([-170.0, -85.0, -170.0, -210.0, -130.0, -2700.0]),
            "MOVE -170.0000 -85.0000 -170.0000 -210.0000 -130.0000 -2700.0000",
        ),
        (
            Command::Move([12.5, 0.0, -90.25, 0.00004, 45.5, 1.0]),
            "MOVE 12.5000 0.0000 -90.2500 0.0000 45.5000 1.0000",
        ),
        (Command::Stop, "STOP"),
        (Command::Bye, "BYE"),
    ];
    for (command, line) in golden {
        assert_eq!(command.to_string(), line);
        assert_eq!(Command::parse(line).unwrap(), command_rounded(&command));
        // As the program splits it: the command word, then single-space separated numbers.
        let (word, rest) = line.split_once(' ').unwrap_or((line, ""));
        assert!(
            arity.contains_key(word),
            "`{word}` is not read by the program"
        );
        let values: Vec<&str> = if rest.is_empty() {
            Vec::new()
        } else {
            rest.split(' ').collect()
        };
        assert_eq!(values.len(), arity[word], "`{line}`");
        assert!(values.iter().all(|v| v.parse::<f64>().is_ok()), "`{line}`");
        assert!(
            rest.len() <= rest_max,
            "`{line}`: {} > {rest_max}",
            rest.len()
        );
        assert!(line.len() <= MAX_LINE);
    }
}

/// The command as it reads back from its line (angles to four decimals).
fn command_rounded(command: &Command) -> Command {
    match command {
        Command::Move(q) => Command::Move(q.map(|v| (v * 1e4).round() / 1e4)),
        other => other.clone(),
    }
}

/// Sample text for the expressions the program concatenates into its replies, in the
/// formats it writes them: `STR_EDIT(CLOCK, 0)` an integer of milliseconds,
/// `joints_text` ' ' + `STR_EDIT(j, 4)` per joint, the pose `STR_EDIT(X, 3)` …
fn term_value(term: &str) -> String {
    let term = term.trim();
    if let Some(text) = term.strip_prefix('\'') {
        return text.strip_suffix('\'').unwrap().to_owned();
    }
    match term {
        "STR_EDIT(CLOCK, 0)" => "1234567".into(),
        "joints_text(vj_now)" => " 10.0000 -20.5000 -90.0000 0.0000 45.2500 -180.0000".into(),
        "ks_version" => "1".into(),
        "STR_EDIT(ERR_NUM, 0)" => "62501".into(),
        "STR_EDIT(vp_now.X, 3)" => "800.000".into(),
        "STR_EDIT(vp_now.Y, 3)" => "-50.125".into(),
        "STR_EDIT(vp_now.Z, 3)" => "1170.000".into(),
        "STR_EDIT(vp_now.A, 4)" => "30.0000".into(),
        "STR_EDIT(vp_now.E, 4)" => "90.0000".into(),
        "STR_EDIT(vp_now.R, 4)" => "-45.0000".into(),
        other => panic!("the program sends `{other}`: give this test a sample of it"),
    }
}

/// Splits a PDL2 string expression at its top-level `+`.
fn terms(expression: &str) -> Vec<&str> {
    let (mut depth, mut quoted, mut start) = (0, false, 0);
    let mut out = Vec::new();
    for (i, c) in expression.char_indices() {
        match c {
            '\'' => quoted = !quoted,
            '(' if !quoted => depth += 1,
            ')' if !quoted => depth -= 1,
            '+' if !quoted && depth == 0 => {
                out.push(&expression[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&expression[start..]);
    out
}

/// Every line the program sends, built from its `send(…)` expressions with sample values.
fn program_replies() -> Vec<String> {
    let code = code();
    code.match_indices("send(")
        .filter(|(i, _)| !code[..*i].ends_with("ROUTINE "))
        .map(|(i, _)| {
            let rest = &code[i + 5..];
            // The argument: up to the `)` that closes `send(`.
            let (mut depth, mut quoted, mut end) = (0, false, 0);
            for (k, c) in rest.char_indices() {
                match c {
                    '\'' => quoted = !quoted,
                    '(' if !quoted => depth += 1,
                    ')' if !quoted && depth == 0 => {
                        end = k;
                        break;
                    }
                    ')' if !quoted => depth -= 1,
                    _ => {}
                }
            }
            terms(&rest[..end]).into_iter().map(term_value).collect()
        })
        .collect()
}

#[test]
fn every_reply_the_program_builds_decodes_as_meant() {
    let replies = program_replies();
    assert_eq!(replies.len(), 16, "{replies:#?}");
    let mut kinds = BTreeMap::new();
    for line in &replies {
        let reply = Reply::parse(line).unwrap_or_else(|e| panic!("`{line}`: {e}"));
        let kind = match &reply {
            Reply::Ok(words) if words.is_empty() => "OK".to_owned(),
            Reply::Ok(words) if words[0] == "NBV-C4G" => {
                assert_eq!(words[1], PROTOCOL_VERSION.to_string());
                "OK NBV-C4G".to_owned()
            }
            Reply::Ok(words) if words.len() == 7 => {
                // JNT and POS answers: a clock and six numbers.
                let (t, v) = Reply::clock_and_joints(words).unwrap();
                assert_eq!(t, 1_234_567.0);
                assert!(v == [10.0, -20.5, -90.0, 0.0, 45.25, -180.0] || v[1] == -50.125);
                "OK clock+6".to_owned()
            }
            Reply::Sample(t, q) | Reply::Done(t, q) => {
                assert_eq!(*t, 1_234_567.0);
                assert_eq!(*q, [10.0, -20.5, -90.0, 0.0, 45.25, -180.0]);
                line.split(' ').next().unwrap().to_owned()
            }
            Reply::Err(code, _) => format!("ERR {}", code.as_str()),
            Reply::Ok(words) => panic!("`{line}`: unexpected OK words {words:?}"),
        };
        *kinds.entry(kind).or_insert(0) += 1;
    }
    let kinds: Vec<(&str, i32)> = kinds.iter().map(|(k, n)| (k.as_str(), *n)).collect();
    assert_eq!(
        kinds,
        [
            ("DONE", 1),
            ("ERR ALARM", 1),
            ("ERR BADARG", 2),
            ("ERR BADCMD", 1),
            ("ERR COLLISION", 1),
            ("ERR LIMIT", 1),
            ("ERR STOPPED", 1),
            ("OK", 4),
            ("OK NBV-C4G", 1),
            ("OK clock+6", 2),
            ("S", 1),
        ]
    );
}

/// Hand-written reply lines in the program's formats (see its header and `send` calls).
#[test]
fn hand_written_reply_lines_decode() {
    let q = [10.0, -20.5, -90.0, 0.0, 45.25, -180.0];
    let golden = [
        (
            "OK NBV-C4G 1",
            Reply::Ok(vec!["NBV-C4G".into(), "1".into()]),
        ),
        ("OK", Reply::Ok(Vec::new())),
        (
            "S 1234567 10.0000 -20.5000 -90.0000 0.0000 45.2500 -180.0000",
            Reply::Sample(1_234_567.0, q),
        ),
        // STR_EDIT may pad; the decoder splits on any run of blanks, and drops a CR.
        (
            "DONE 1234587  10.0000 -20.5000 -90.0000  0.0000 45.2500 -180.0000\r",
            Reply::Done(1_234_587.0, q),
        ),
        (
            "ERR LIMIT target outside the joint strokes",
            Reply::Err(ErrorCode::Limit, "target outside the joint strokes".into()),
        ),
        (
            "ERR STOPPED by the client",
            Reply::Err(ErrorCode::Stopped, "by the client".into()),
        ),
        (
            "ERR COLLISION 1234600 robot collision-detection",
            Reply::Err(
                ErrorCode::Collision,
                "1234600 robot collision-detection".into(),
            ),
        ),
        (
            "ERR ALARM controller alarm 62501",
            Reply::Err(ErrorCode::Alarm, "controller alarm 62501".into()),
        ),
        (
            "ERR BADCMD unknown command",
            Reply::Err(ErrorCode::BadCommand, "unknown command".into()),
        ),
    ];
    for (line, reply) in golden {
        assert_eq!(Reply::parse(line).unwrap(), reply, "`{line}`");
    }
    // JNT's answer carries the clock and the joints.
    let Reply::Ok(words) =
        Reply::parse("OK 1234567 10.0000 -20.5000 -90.0000 0.0000 45.2500 -180.0000").unwrap()
    else {
        panic!("not OK")
    };
    assert_eq!(Reply::clock_and_joints(&words).unwrap(), (1_234_567.0, q));
}
