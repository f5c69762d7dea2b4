//! The NGC language of the G-code reader against hand-derived values: LinuxCNC's operators
//! and functions, the parameter timing rule, locals and globals, subroutines with arguments
//! and values, control flow, Fanuc-style M98/M99, and every budget a typed error (a loop that
//! never ends, runaway recursion, an expression nested too deep).

use deflect_core::LoadError;
use deflect_core::io::gcode::{self, GcodeOptions, MAX_BLOCKS, MAX_CALL_DEPTH};
use deflect_core::machining::{Motion, Program};

fn read(text: &str) -> Program {
    gcode::from_str(text, &GcodeOptions::default()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fault(text: &str) -> String {
    match gcode::from_str(text, &GcodeOptions::default()) {
        Err(e) => e.to_string(),
        Ok(p) => panic!(
            "expected an error for {text:?}, got {} moves",
            p.moves.len()
        ),
    }
}

/// The x of each move's end [mm].
fn xs(p: &Program) -> Vec<f64> {
    p.moves
        .iter()
        .map(|m| (m.end.x * 1e6).round() / 1e3)
        .collect()
}

/// The value of an expression, read through a move to X = value mm.
fn value(expr: &str) -> f64 {
    let p = read(&format!("G0 X-1000\nG0 X{expr}\n"));
    p.moves.last().map(|m| m.end.x * 1e3).unwrap()
}

#[test]
fn operators_and_functions_are_linuxcncs() {
    let close = |e: &str, v: f64| {
        let got = value(e);
        assert!((got - v).abs() < 1e-9, "{e} = {got}, expected {v}");
    };
    // Every binary operator is left-associative: 2 ** 3 ** 2 = (2^3)^2.
    close("[2 ** 3 ** 2]", 64.0);
    close("[100 / 10 / 5]", 2.0);
    close("[10 - 4 - 3]", 3.0);
    close("[1 + 2 * 3 ** 2 - 4 / 2]", 17.0);
    // The sign binds tighter than **: [-2 ** 2] = 4.
    close("[-2 ** 2]", 4.0);
    close("[2 * -3]", -6.0);
    // MOD into [0, |b|).
    close("[-5 MOD 3]", 1.0);
    close("[5 MOD -3]", 2.0);
    close("[5.5 MOD 2]", 1.5);
    // Comparisons and logic give 0 or 1; EQ within 0.0001, GT exact; AND/OR/XOR one level.
    close("[1 EQ 1.00009]", 1.0);
    close("[1 NE 1.00009]", 0.0);
    close("[1 LT 1.00009]", 1.0);
    close("[3 GT 2 GT 1]", 0.0);
    close("[1 OR 0 AND 0]", 0.0);
    close("[2 XOR 3]", 0.0);
    close("[1 + 1 EQ 2]", 1.0);
    // Degrees; FIX is floor, FUP ceil, ROUND half away from zero.
    close("SIN[30]", 0.5);
    close("[COS[60] + TAN[45]]", 1.5);
    close("[ASIN[0.5] + ACOS[0.5]]", 90.0);
    close("ATAN[1]/[-1]", 135.0);
    close(
        "[FIX[-2.5] + FUP[-2.5] + ROUND[2.5] + ROUND[-0.5]]",
        -3.0 - 2.0 + 3.0 - 1.0,
    );
    close("[SQRT[16] + ABS[-3] + LN[EXP[2]]]", 9.0);
    // Spaces and case do not matter.
    close("[ s i n [ 90 ] * 1 0 ]", 10.0);
    // Domain errors are refused by name.
    assert!(fault("G0 X[1/0]\n").contains("a divisor other than 0"));
    assert!(fault("G0 X[SQRT[-1]]\n").contains("SQRT"));
    assert!(fault("G0 X[LN[0]]\n").contains("LN"));
    assert!(fault("G0 X[ACOS[2]]\n").contains("ACOS"));
    assert!(fault("G0 X[-2 ** 0.5]\n").contains("non-integer power"));
    assert!(fault("G0 X1e3\n").contains("a G code") || fault("G0 X1e3\n").contains("E"));
}

#[test]
fn settings_take_effect_after_their_line() {
    // #1 = 2 and X#1 on one line: the move uses the old #1 (5).
    let p = read("#1 = 5\n#1 = 2 G0 X#1\nG0 X#1\n");
    assert_eq!(xs(&p), [5.0, 2.0]);
    // Numbered settings in order, last wins; indirection ##; #[expr].
    let p = read("#1 = 3\n#3 = 7 #3 = 9\n#[1 + 1] = ##1\nG0 X#2\n");
    assert_eq!(xs(&p), [9.0]);
    // A named parameter exists (as 0) from its '=' on; reading an unset one is an error.
    let p = read("#<x> = [#<x> + 4]\nG0 X#<x>\n");
    assert_eq!(xs(&p), [4.0]);
    assert!(fault("G0 X#<nothere>\n").contains("#<nothere>"));
    // An unset numbered parameter is 0; EXISTS tells.
    let p = read("G0 X[#77 + 1]\n#<a> = 1\nG0 X[EXISTS[#<a>] + EXISTS[#<b>] * 10 + 2]\n");
    assert_eq!(xs(&p), [1.0, 3.0]);
    // Read-only parameters refuse a setting.
    assert!(fault("#5420 = 1\n").contains("read-only"));
    assert!(fault("#<_x> = 1\n").contains("read-only"));
    assert!(fault("#5602 = 1\n").contains("1..=5601"));
    // The position parameters read the program's own coordinates, in its unit.
    let p = read("G0 X12.5\nG0 Y[#5420 * 2]\nG20\nG0 Z[#<_x> * 25.4 / 1000 * 0 + #5420]\n");
    let last = p.moves.last().unwrap().end;
    assert!((last.y - 0.025).abs() < 1e-15);
    assert!((last.z - 12.5e-3).abs() < 1e-12, "{}", last.z);
}

#[test]
fn subroutines_pass_arguments_return_values_and_keep_locals_apart() {
    let p = read(
        "#1 = 100\n#<_g> = 1\n\
         o<add> sub\n  #<local> = [#1 + #2]\n  #<_g> = [#<_g> + 1]\no<add> endsub [#<local>]\n\
         o<add> call [3] [4]\nG0 X[#<_value>]\nG0 X#1\nG0 X#<_g>\nG0 X[EXISTS[#<local>]]\nM2\n",
    );
    // The value 7, the caller's #1 restored (100), the global changed (2), no local leak.
    assert_eq!(xs(&p), [7.0, 100.0, 2.0, 0.0]);
    // A sub defined after its call, below M2; arguments past the given ones are 0.
    let p = read(
        "o<later> call [5]\nG0 X#<_value>\nM2\no<later> sub\no<later> return [#1 + #2]\no<later> endsub\n",
    );
    assert_eq!(xs(&p), [5.0]);
    // Recursion within the depth budget: 3! = 6.
    let p = read(
        "o<fact> sub\n  o1 if [#1 LE 1]\n    o<fact> return [1]\n  o1 endif\n  \
         o<fact> call [#1 - 1]\n  o<fact> return [#1 * #<_value>]\no<fact> endsub\n\
         o<fact> call [3]\nG0 X#<_value>\nM2\n",
    );
    assert_eq!(xs(&p), [6.0]);
    assert!(fault("o<none> call\n").contains("a subroutine o<none> defined in this program"));
    assert!(fault("o<s> endsub\n").contains("inside a called subroutine"));
}

#[test]
fn control_flow_runs_as_linuxcnc_runs_it() {
    // if / elseif / else: the first true branch only.
    let branch = |v: i32| {
        read(&format!(
            "#1 = {v}\no1 if [#1 EQ 1]\nG0 X1\no1 elseif [#1 EQ 2]\nG0 X2\no1 elseif [#1 GT 0]\n\
             G0 X3\no1 else\nG0 X4\no1 endif\nG0 Z1\n"
        ))
    };
    assert_eq!(xs(&branch(1))[0], 1.0);
    assert_eq!(xs(&branch(2))[0], 2.0);
    assert_eq!(xs(&branch(7))[0], 3.0);
    assert_eq!(xs(&branch(-1))[0], 4.0);
    // while with continue and break; do ... while runs at least once.
    let p = read(
        "#1 = 0\no2 while [#1 LT 10]\n#1 = [#1 + 1]\no3 if [#1 EQ 2]\no2 continue\no3 endif\n\
         o4 if [#1 EQ 5]\no2 break\no4 endif\nG0 X#1\no2 endwhile\n\
         o5 do\nG0 X[#1 * 10]\no5 while [0]\n",
    );
    assert_eq!(xs(&p), [1.0, 3.0, 4.0, 50.0]);
    // repeat's count rounds half to even: [2.5] runs twice, [3.5] four times.
    let p = read(
        "#1 = 0\no6 repeat [2.5]\n#1 = [#1 + 1]\no6 endrepeat\no7 repeat [3.5]\n#1 = [#1 + 1]\no7 endrepeat\nG0 X#1\n",
    );
    assert_eq!(xs(&p), [6.0]);
    // The same label in two subroutines is two labels.
    let p = read(
        "o<a> sub\no1 if [1]\nG0 X1\no1 endif\no<a> endsub\no<b> sub\no1 if [0]\nG0 X9\no1 else\nG0 X2\no1 endif\no<b> endsub\n\
         o<a> call\no<b> call\nM2\n",
    );
    assert_eq!(xs(&p), [1.0, 2.0]);
    // Fanuc style: M98 P100 L2 runs O100 ... M99 twice, sharing #1.
    let p = read("#1 = 0\nM98 P100 L2\nG0 X[#1 * 5]\nM30\nO100\n#1 = [#1 + 1]\nM99\n");
    assert_eq!(xs(&p), [10.0]);
    // Lines after the program end are not read, whatever they hold.
    let p = read("G0 X1\nM2\nG0 X2 &&& garbage\n");
    assert_eq!(xs(&p), [1.0]);
    // A false branch is skipped unread but for its O-words.
    let p = read("o1 if [0]\nG0 X[1/0] ###\no1 endif\nG0 X3\n");
    assert_eq!(xs(&p), [3.0]);
    assert!(fault("o1 if [1]\no1 endwhile\n").contains("o<1> while before o<1> endwhile"));
    assert!(fault("o1 if [0]\nG0 X1\n").contains("before the end of the file"));
}

#[test]
fn budgets_are_typed_errors_not_hangs() {
    // A loop that never ends: MAX_BLOCKS lines, then a typed error naming the budget.
    match gcode::from_str(
        "o1 while [1]\n#1 = [#1 + 1]\no1 endwhile\n",
        &GcodeOptions::default(),
    ) {
        Err(LoadError::ProgramBudget {
            budget,
            limit,
            line,
            ..
        }) => {
            assert_eq!((budget, limit), ("MAX_BLOCKS", MAX_BLOCKS));
            assert!((1..=3).contains(&line));
        }
        other => panic!("{other:?}"),
    }
    // Runaway recursion: MAX_CALL_DEPTH nested calls.
    let e = fault("o<r> sub\no<r> call\no<r> endsub\no<r> call\nM2\n");
    assert!(
        e.contains(&format!("at most {MAX_CALL_DEPTH} nested subroutine calls")),
        "{e}"
    );
    // An expression nested past MAX_EXPRESSION_DEPTH.
    let deep = format!("G0 X{}1{}\n", "[".repeat(200), "]".repeat(200));
    assert!(fault(&deep).contains("MAX_EXPRESSION_DEPTH"));
    let shallow = format!("G0 X{}1{}\n", "[".repeat(100), "]".repeat(100));
    assert_eq!(xs(&read(&shallow)), [1.0]);
    // A loop making more moves than MAX_MOVES stops there, typed.
    let e = gcode::from_str(
        "#1 = 0\no1 while [1]\nG0 X[#1 MOD 2]\n#1 = [#1 + 1]\no1 endwhile\n",
        &GcodeOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            LoadError::TooLarge { .. } | LoadError::ProgramBudget { .. }
        ),
        "{e}"
    );
}

#[test]
fn comments_messages_and_block_delete() {
    // Only paren comments and ';' are comments; (MSG,...) and (DEBUG,...) move nothing;
    // (ABORT,...) stops with its text.
    let p = read("G0 X1 (MSG, hello) ; X9\n(DEBUG, #1)\n/G0 X2\n");
    assert_eq!(xs(&p), [1.0, 2.0]);
    let o = GcodeOptions {
        block_delete: true,
        ..GcodeOptions::default()
    };
    let p = gcode::from_str("G0 X1\n/G0 X2\n", &o).unwrap();
    assert_eq!(xs(&p), [1.0]);
    assert!(fault("G0 X1\n(ABORT,stop here)\n").contains("(ABORT,stop here)"));
    // A program may start and end with '%'; what follows the closing '%' is not read.
    let p = read("%\nG0 X1\n%\nthis is not G-code\n");
    assert_eq!(xs(&p), [1.0]);
    // Motion modes stay: a bare axis word moves in the last mode.
    let p = read("G1 X1 F100\nX2\nG0 X3\nX4\n");
    assert!(
        matches!(p.moves[1].motion, Motion::Linear) && matches!(p.moves[3].motion, Motion::Rapid)
    );
}
