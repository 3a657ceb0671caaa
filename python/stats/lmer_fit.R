# Fits linear mixed models with lme4 (Bates, Maechler, Bolker & Walker 2015, J Stat Softw 67(1)) and tests
# their fixed effects with lmerTest's small-sample degrees of freedom (Kuznetsova, Brockhoff & Christensen 2017,
# J Stat Softw 82(13)): Satterthwaite (1946) or Kenward & Roger (1997, through pbkrtest).
# Run by calligraphy.mixed_models (python), never by hand, in one of two ways:
#   Rscript lmer_fit.R FOLDER FORMULA DDF    one fit; exit status 0 when its results were written, 1 with a
#                                            message on standard error otherwise
#   Rscript lmer_fit.R --serve               fits one request a line from standard input until end of input
#                                            (loading lme4 and lmerTest takes longer than most fits, so a report
#                                            loads them once). The protocol is framed so that no text can break
#                                            it: every field is UTF-8 written as lower-case hex, so a formula
#                                            with a line break or a tab is one field. A request is the line
#                                              @@calligraphy-request ID FOLDER FORMULA DDF
#                                            and its one reply the line
#                                              @@calligraphy-reply ID ok FILES      (FILES: name=bytes;... of
#                                                                                   the result files written)
#                                              @@calligraphy-reply ID error MESSAGE
#                                            where ID is the request's (decimal) and FILES and MESSAGE are hex.
#                                            Before any request R says whether the packages a fit needs load,
#                                            in its first frame (so that one R start both checks and serves):
#                                              @@calligraphy-ready ok
#                                              @@calligraphy-ready missing PACKAGE  (hex; R then ends, status 3)
#                                            naming the first of lme4, lmerTest and pbkrtest that does not load.
#                                            Other lines (a package's chatter) carry no marker and are ignored.
# FOLDER holds data.csv (UTF-8; an empty field is a missing value), types.csv (column, type: "number" or
# "text", each column of data.csv) and levels.csv (factor, level: each factor's levels in order, reference
# first); a fit writes fixed.csv, random.csv, anova.csv (one F test per term) and fit.csv (key, value) there
# (a fit that did not converge or is singular says so in fit.csv). When the first factor of levels.csv (the
# compared one) has three or more levels and is a term of the model, pairs.csv holds every pairwise contrast
# of its estimated marginal means (emmeans, Lenth 2024; the same df method), later level - earlier level, with
# p raw and Holm-adjusted among them; fit.csv's "pairs" says why there are none.
arguments <- commandArgs(trailingOnly = TRUE)
serving <- length(arguments) == 1 && arguments[1] == "--serve"
if (serving) {
  # Loading is the check (an install missing one of its own dependencies does not load), and library() below
  # then attaches the namespaces already loaded: the check costs this R no second load.
  for (package in c("lme4", "lmerTest", "pbkrtest")) {
    if (!suppressPackageStartupMessages(requireNamespace(package, quietly = TRUE))) {
      cat("@@calligraphy-ready missing ",
          paste(as.character(charToRaw(enc2utf8(package))), collapse = ""), "\n", sep = "")
      flush(stdout())
      quit(save = "no", status = 3)
    }
  }
}
suppressPackageStartupMessages({
  library(lme4)
  library(lmerTest)
})
has_emmeans <- requireNamespace("emmeans", quietly = TRUE)

fit_model <- function(folder, formula_text, ddf) {
  model_formula <- stats::as.formula(formula_text)
  # Only an empty field is missing, and a column of text stays text: a condition called "NA", "TRUE" or "T"
  # or subjects called "1" and "01" are levels as written, never R's missing value, a logical or one number.
  classes <- NA
  if (file.exists(file.path(folder, "types.csv"))) {
    types <- utils::read.csv(file.path(folder, "types.csv"), encoding = "UTF-8", stringsAsFactors = FALSE,
                             colClasses = "character", na.strings = character(0))
    classes <- stats::setNames(ifelse(types$type == "number", "numeric", "character"), types$column)
  }
  data <- utils::read.csv(file.path(folder, "data.csv"), encoding = "UTF-8", stringsAsFactors = FALSE,
                          check.names = FALSE, colClasses = classes, na.strings = "")
  levels_table <- utils::read.csv(file.path(folder, "levels.csv"), encoding = "UTF-8", stringsAsFactors = FALSE,
                                  colClasses = "character", na.strings = character(0))
  for (factor_name in unique(levels_table$factor)) {
    ordered_levels <- levels_table$level[levels_table$factor == factor_name]
    # An unordered factor gets R's default treatment coding, the first level (the control) the reference: each
    # other level's coefficient, named factor followed by level, is its difference from the control.
    data[[factor_name]] <- factor(as.character(data[[factor_name]]), levels = ordered_levels)
  }

  messages <- character(0)
  fit <- withCallingHandlers(
    lmerTest::lmer(model_formula, data = data, REML = TRUE),
    warning = function(w) {
      messages <<- c(messages, conditionMessage(w))
      invokeRestart("muffleWarning")
    },
    message = function(m) {
      messages <<- c(messages, trimws(conditionMessage(m)))
      invokeRestart("muffleMessage")
    })
  # lme4 files its "boundary (singular) fit" note with the convergence messages; singularity is reported apart.
  convergence <- fit@optinfo$conv$lme4$messages
  convergence <- convergence[!grepl("singular", convergence)]
  messages <- unique(c(messages, convergence))
  singular <- lme4::isSingular(fit)

  coefficients <- summary(fit, ddf = ddf)$coefficients
  df <- coefficients[, "df"]
  half_width <- stats::qt(0.975, df) * coefficients[, "Std. Error"]
  fixed <- data.frame(term = rownames(coefficients), estimate = coefficients[, "Estimate"],
                      std_error = coefficients[, "Std. Error"], df = df, t = coefficients[, "t value"],
                      p = coefficients[, "Pr(>|t|)"], ci95_low = coefficients[, "Estimate"] - half_width,
                      ci95_high = coefficients[, "Estimate"] + half_width)
  utils::write.csv(fixed, file.path(folder, "fixed.csv"), row.names = FALSE, fileEncoding = "UTF-8")

  # One F test per term (lmerTest's type III table, the same df method): a factor of several levels, such as a
  # crossover's sequence, is tested as a whole.
  terms <- stats::anova(fit, ddf = ddf)
  anova_table <- data.frame(term = rownames(terms), num_df = terms[, "NumDF"], den_df = terms[, "DenDF"],
                            f = terms[, "F value"], p = terms[, "Pr(>F)"])
  utils::write.csv(anova_table, file.path(folder, "anova.csv"), row.names = FALSE, fileEncoding = "UTF-8")

  components <- as.data.frame(lme4::VarCorr(fit))
  # One row per variance or covariance: "subject" for a random intercept alone, "subject (Intercept)" and
  # "subject factorB" with random slopes, "subject cov (Intercept) factorB" for their covariance.
  component_name <- ifelse(is.na(components$var1), components$grp,
                           ifelse(is.na(components$var2),
                                  ifelse(table(components$grp)[components$grp] > 1,
                                         paste(components$grp, components$var1), components$grp),
                                  paste(components$grp, "cov", components$var1, components$var2)))
  random <- data.frame(group = component_name, variance = components$vcov)
  utils::write.csv(random, file.path(folder, "random.csv"), row.names = FALSE, fileEncoding = "UTF-8")

  pairs_status <- write_pairs(fit, folder, levels_table, ddf)

  info <- data.frame(
    key = c("n_observations", "singular", "converged", "messages", "ddf", "lme4_version", "lmertest_version",
            "r_version", "pairs"),
    value = c(stats::nobs(fit), singular, length(convergence) == 0, paste(messages, collapse = "; "), ddf,
              as.character(utils::packageVersion("lme4")), as.character(utils::packageVersion("lmerTest")),
              paste(R.version$major, R.version$minor, sep = "."), pairs_status))
  utils::write.csv(info, file.path(folder, "fit.csv"), row.names = FALSE, fileEncoding = "UTF-8")
}

# Every pairwise contrast of the compared factor's estimated marginal means (emmeans, averaged over the other
# factors with equal weights), with the fit's df method; "ok", or why there are none.
write_pairs <- function(fit, folder, levels_table, ddf) {
  if (nrow(levels_table) == 0) return("no factor")
  compared <- levels_table$factor[1]
  if (sum(levels_table$factor == compared) < 3) return("fewer than 3 levels")
  if (!(compared %in% all.vars(stats::formula(fit, fixed.only = TRUE)))) return("not a fixed term")
  if (!has_emmeans) return("emmeans is not installed (Debian: r-cran-emmeans)")
  tryCatch({
    means <- suppressMessages(emmeans::emmeans(fit, specs = compared,
                                               lmer.df = if (ddf == "Kenward-Roger") "kenward-roger" else "satterthwaite"))
    raw <- as.data.frame(summary(graphics::pairs(means, reverse = TRUE, adjust = "none"), infer = c(TRUE, TRUE)))
    holm <- as.data.frame(summary(graphics::pairs(means, reverse = TRUE, adjust = "holm"), infer = c(FALSE, TRUE)))
    utils::write.csv(data.frame(contrast = raw$contrast, estimate = raw$estimate, std_error = raw$SE, df = raw$df,
                                t = raw$t.ratio, p = raw$p.value, p_holm = holm$p.value, ci95_low = raw$lower.CL,
                                ci95_high = raw$upper.CL),
                     file.path(folder, "pairs.csv"), row.names = FALSE, fileEncoding = "UTF-8")
    "ok"
  }, error = function(e) paste("emmeans failed:", gsub("[\r\n\t]+", " ", conditionMessage(e))))
}

# The serve protocol's fields: UTF-8 text as lower-case hex, which has no space, tab or line break.
text_to_hex <- function(text) paste(as.character(charToRaw(enc2utf8(text))), collapse = "")
hex_to_text <- function(hex) {
  if (nchar(hex) %% 2 != 0 || grepl("[^0-9a-f]", hex)) stop("a request field is not hex")
  if (!nzchar(hex)) return("")
  text <- rawToChar(as.raw(strtoi(substring(hex, seq(1, nchar(hex), 2), seq(2, nchar(hex), 2)), 16L)))
  Encoding(text) <- "UTF-8"
  if (!validUTF8(text)) stop("a request field is not UTF-8")
  text
}

if (serving) {
  cat("@@calligraphy-ready ok\n")
  flush(stdout())
  requests <- file("stdin", open = "r")
  repeat {
    line <- readLines(requests, n = 1, encoding = "UTF-8")
    if (length(line) == 0) break
    request <- strsplit(line, " ", fixed = TRUE)[[1]]
    if (length(request) < 2 || request[1] != "@@calligraphy-request" || !grepl("^[0-9]+$", request[2])) next
    reply <- tryCatch({
      if (length(request) != 5) stop("expected ID, FOLDER, FORMULA and DDF")
      folder <- hex_to_text(request[3])
      fit_model(folder, hex_to_text(request[4]), hex_to_text(request[5]))
      files <- c("fixed.csv", "random.csv", "anova.csv", "fit.csv")
      if (file.exists(file.path(folder, "pairs.csv"))) files <- c(files, "pairs.csv")
      paste("ok", text_to_hex(paste0(files, "=", file.size(file.path(folder, files)), collapse = ";")))
    }, error = function(e) paste("error", text_to_hex(conditionMessage(e))))
    cat("@@calligraphy-reply ", request[2], " ", reply, "\n", sep = "")
    flush(stdout())
  }
} else if (length(arguments) == 3) {
  fit_model(arguments[1], arguments[2], arguments[3])
} else {
  stop("usage: Rscript lmer_fit.R FOLDER FORMULA DDF, or Rscript lmer_fit.R --serve")
}
